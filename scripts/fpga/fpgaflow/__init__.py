"""The FPGA flow of the generated accelerator as a package: tools, the
emitted design, ECP5 synthesis and place and route, the Xilinx estimate, the
area breakdown and the report. scripts/fpga/flow.py is its command line.
Standard library only."""
