// The ECP5 implementation of the generator's RegisteredReadMemory_<rows>x<width>
// (src/bpaccel/RegisteredReadMemory.scala): a simple dual-port memory whose read
// data passes one register, two cycles from a read's row to its data, held until
// the next read's data arrives.
//
// Built from one row of DP16KD block RAMs, each as wide as the depth allows
// (18 bits up to 1024 rows, 9 bits up to 2048); port A writes, port B reads
// with the block RAM's own output register on (REGMODE_B = "OUTREG"), so the
// register of the Chisel description sits inside the block RAM: its
// clock-to-output is about 1 ns instead of the unregistered read's 5.6 ns.
// Port B's read latch only loads on an enabled read (CEB) and the output
// register loads from it every cycle (OCEB = 1), which is exactly "the output
// register loads one cycle after an enabled read". Yosys cannot infer OUTREG
// (it only folds the address register into the block RAM), so
// scripts/fpga/flow.py puts this module in place of the Chisel one. A row read
// in the cycle it is written gives undefined data here (port collision); the
// Chisel description gives poison for it, so the design's tests show that no
// such data is used. RegisteredReadMemorySpec checks this module against the
// Chisel one, cycle by cycle, on a DP16KD model.
module Ecp5RegisteredReadMemory #(
  parameter integer ROWS = 2048,
  parameter integer WIDTH = 32,
  parameter integer ROW_BITS = 11,
  // Only the equivalence test sets another value, to show its check fails.
  parameter REGMODE = "OUTREG"
) (
  input                 clock,
  input                 write_enable,
  input  [ROW_BITS-1:0] write_row,
  input  [WIDTH-1:0]    write_data,
  input                 read_enable,
  input  [ROW_BITS-1:0] read_row,
  output [WIDTH-1:0]    read_data
);
  localparam integer TILE_WIDTH = (ROWS <= 1024) ? 18 : 9;
  localparam integer TILES = (WIDTH + TILE_WIDTH - 1) / TILE_WIDTH;
  // The word address sits above the bits that select within a word (x9: 3, x18: 4);
  // in x18 mode address bits 1:0 are the write port's byte enables.
  localparam integer ADDRESS_SHIFT = (TILE_WIDTH == 18) ? 4 : 3;
  localparam [13:0] BYTE_ENABLES = (TILE_WIDTH == 18) ? 14'd3 : 14'd0;

  generate
    if (ROWS < 1 || ROWS > 2048 || (1 << ROW_BITS) < ROWS || ROW_BITS > 11)
      initial $fatal(1, "Ecp5RegisteredReadMemory: %0d rows with %0d row bits is not supported", ROWS, ROW_BITS);
  endgenerate

  wire [13:0] write_address = (write_row << ADDRESS_SHIFT) | BYTE_ENABLES;
  wire [13:0] read_address  = read_row << ADDRESS_SHIFT;
  wire [TILES*TILE_WIDTH-1:0] write_padded = write_data;
  wire [TILES*TILE_WIDTH-1:0] read_padded;
  assign read_data = read_padded[WIDTH-1:0];

  genvar t;
  generate
    for (t = 0; t < TILES; t = t + 1) begin : tile
      wire [17:0] tile_write = write_padded[t*TILE_WIDTH +: TILE_WIDTH];
      wire [17:0] tile_read;
      assign read_padded[t*TILE_WIDTH +: TILE_WIDTH] = tile_read[TILE_WIDTH-1:0];
      DP16KD #(
        .DATA_WIDTH_A(TILE_WIDTH),
        .DATA_WIDTH_B(TILE_WIDTH),
        .REGMODE_A("NOREG"),
        .REGMODE_B(REGMODE),
        .RESETMODE("SYNC"),
        .ASYNC_RESET_RELEASE("SYNC"),
        .CSDECODE_A("0b000"),
        .CSDECODE_B("0b000"),
        .WRITEMODE_A("NORMAL"),
        .WRITEMODE_B("NORMAL"),
        .GSR("AUTO")
      ) ram (
        .CLKA(clock), .CEA(write_enable), .OCEA(1'b0), .WEA(write_enable), .RSTA(1'b0),  // port A writes
        .CSA0(1'b0), .CSA1(1'b0), .CSA2(1'b0),
        .ADA0(write_address[0]), .ADA1(write_address[1]), .ADA2(write_address[2]), .ADA3(write_address[3]), .ADA4(write_address[4]), .ADA5(write_address[5]), .ADA6(write_address[6]), .ADA7(write_address[7]), .ADA8(write_address[8]), .ADA9(write_address[9]), .ADA10(write_address[10]), .ADA11(write_address[11]), .ADA12(write_address[12]), .ADA13(write_address[13]),
        .DIA0(tile_write[0]), .DIA1(tile_write[1]), .DIA2(tile_write[2]), .DIA3(tile_write[3]), .DIA4(tile_write[4]), .DIA5(tile_write[5]), .DIA6(tile_write[6]), .DIA7(tile_write[7]), .DIA8(tile_write[8]), .DIA9(tile_write[9]), .DIA10(tile_write[10]), .DIA11(tile_write[11]), .DIA12(tile_write[12]), .DIA13(tile_write[13]), .DIA14(tile_write[14]), .DIA15(tile_write[15]), .DIA16(tile_write[16]), .DIA17(tile_write[17]),
        .DOA0(), .DOA1(), .DOA2(), .DOA3(), .DOA4(), .DOA5(), .DOA6(), .DOA7(), .DOA8(), .DOA9(), .DOA10(), .DOA11(), .DOA12(), .DOA13(), .DOA14(), .DOA15(), .DOA16(), .DOA17(),
        .CLKB(clock), .CEB(read_enable), .OCEB(1'b1), .WEB(1'b0), .RSTB(1'b0),  // port B reads
        .CSB0(1'b0), .CSB1(1'b0), .CSB2(1'b0),
        .ADB0(read_address[0]), .ADB1(read_address[1]), .ADB2(read_address[2]), .ADB3(read_address[3]), .ADB4(read_address[4]), .ADB5(read_address[5]), .ADB6(read_address[6]), .ADB7(read_address[7]), .ADB8(read_address[8]), .ADB9(read_address[9]), .ADB10(read_address[10]), .ADB11(read_address[11]), .ADB12(read_address[12]), .ADB13(read_address[13]),
        .DIB0(1'b0), .DIB1(1'b0), .DIB2(1'b0), .DIB3(1'b0), .DIB4(1'b0), .DIB5(1'b0), .DIB6(1'b0), .DIB7(1'b0), .DIB8(1'b0), .DIB9(1'b0), .DIB10(1'b0), .DIB11(1'b0), .DIB12(1'b0), .DIB13(1'b0), .DIB14(1'b0), .DIB15(1'b0), .DIB16(1'b0), .DIB17(1'b0),
        .DOB0(tile_read[0]), .DOB1(tile_read[1]), .DOB2(tile_read[2]), .DOB3(tile_read[3]), .DOB4(tile_read[4]), .DOB5(tile_read[5]), .DOB6(tile_read[6]), .DOB7(tile_read[7]), .DOB8(tile_read[8]), .DOB9(tile_read[9]), .DOB10(tile_read[10]), .DOB11(tile_read[11]), .DOB12(tile_read[12]), .DOB13(tile_read[13]), .DOB14(tile_read[14]), .DOB15(tile_read[15]), .DOB16(tile_read[16]), .DOB17(tile_read[17])
      );
    end
  endgenerate
endmodule
