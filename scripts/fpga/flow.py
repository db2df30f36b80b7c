#!/usr/bin/env python3
"""The FPGA flow of one emitted configuration: see fpgaflow/driver.py (or --help)."""
import sys

from fpgaflow.driver import main

if __name__ == "__main__":
    sys.exit(main())
