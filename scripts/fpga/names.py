#!/usr/bin/env python3
"""Prints a configuration's name (folders, results/fpga/<name>.json): see fpgaflow/names.py."""
import sys

from fpgaflow.names import main

if __name__ == "__main__":
    sys.exit(main())
