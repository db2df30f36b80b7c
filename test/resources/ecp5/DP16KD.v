// A behavioural model of the ECP5 DP16KD block RAM, for the equivalence test of
// scripts/fpga/ecp5/Ecp5RegisteredReadMemory.v (RegisteredReadMemorySpec) only.
// Neither Yosys nor nextpnr ship one (their DP16KD is a black box), so this
// follows Lattice's ECP5 sysMEM usage guide (TN1264) for what that module uses:
//  - data widths 9 (2048 words, address pins 13:3) and 18 (1024 words, address
//    pins 13:4; in a write, pins 1:0 enable the low and high 9 bits);
//  - a port reads when CE is high and WE low, writes when both are high; in
//    WRITEMODE NORMAL a write leaves the port's output unchanged;
//  - REGMODE NOREG: the output is the read latch, loaded at the read's clock
//    edge; REGMODE OUTREG: the output is a register that loads the latch at
//    each clock edge with OCE high (one more cycle);
//  - RST clears the latch and the register (synchronous).
// Anything else (other widths, modes, chip selects) stops the simulation.
module DP16KD(
  input DIA17, DIA16, DIA15, DIA14, DIA13, DIA12, DIA11, DIA10, DIA9, DIA8, DIA7, DIA6, DIA5, DIA4, DIA3, DIA2, DIA1, DIA0,
  input ADA13, ADA12, ADA11, ADA10, ADA9, ADA8, ADA7, ADA6, ADA5, ADA4, ADA3, ADA2, ADA1, ADA0,
  input CEA, OCEA, CLKA, WEA, RSTA,
  input CSA2, CSA1, CSA0,
  output DOA17, DOA16, DOA15, DOA14, DOA13, DOA12, DOA11, DOA10, DOA9, DOA8, DOA7, DOA6, DOA5, DOA4, DOA3, DOA2, DOA1, DOA0,
  input DIB17, DIB16, DIB15, DIB14, DIB13, DIB12, DIB11, DIB10, DIB9, DIB8, DIB7, DIB6, DIB5, DIB4, DIB3, DIB2, DIB1, DIB0,
  input ADB13, ADB12, ADB11, ADB10, ADB9, ADB8, ADB7, ADB6, ADB5, ADB4, ADB3, ADB2, ADB1, ADB0,
  input CEB, OCEB, CLKB, WEB, RSTB,
  input CSB2, CSB1, CSB0,
  output DOB17, DOB16, DOB15, DOB14, DOB13, DOB12, DOB11, DOB10, DOB9, DOB8, DOB7, DOB6, DOB5, DOB4, DOB3, DOB2, DOB1, DOB0
);
  parameter integer DATA_WIDTH_A = 18;
  parameter integer DATA_WIDTH_B = 18;
  parameter REGMODE_A = "NOREG";
  parameter REGMODE_B = "NOREG";
  parameter RESETMODE = "SYNC";
  parameter ASYNC_RESET_RELEASE = "SYNC";
  parameter CSDECODE_A = "0b000";
  parameter CSDECODE_B = "0b000";
  parameter WRITEMODE_A = "NORMAL";
  parameter WRITEMODE_B = "NORMAL";
  parameter GSR = "ENABLED";

  initial begin
    if (!(DATA_WIDTH_A == 9 || DATA_WIDTH_A == 18) || !(DATA_WIDTH_B == 9 || DATA_WIDTH_B == 18))
      $fatal(1, "DP16KD model: only data widths 9 and 18 are modelled");
    if (!(REGMODE_A == "NOREG" || REGMODE_A == "OUTREG") || !(REGMODE_B == "NOREG" || REGMODE_B == "OUTREG"))
      $fatal(1, "DP16KD model: REGMODE must be NOREG or OUTREG");
    if (WRITEMODE_A != "NORMAL" || WRITEMODE_B != "NORMAL" || RESETMODE != "SYNC")
      $fatal(1, "DP16KD model: only WRITEMODE NORMAL and RESETMODE SYNC are modelled");
  end

  // 2048 nine-bit words; an 18-bit word w is words 2w (bits 8:0) and 2w+1 (bits 17:9).
  reg [8:0] words [0:2047];

  wire [17:0] dia = {DIA17, DIA16, DIA15, DIA14, DIA13, DIA12, DIA11, DIA10, DIA9, DIA8, DIA7, DIA6, DIA5, DIA4, DIA3, DIA2, DIA1, DIA0};
  wire [17:0] dib = {DIB17, DIB16, DIB15, DIB14, DIB13, DIB12, DIB11, DIB10, DIB9, DIB8, DIB7, DIB6, DIB5, DIB4, DIB3, DIB2, DIB1, DIB0};
  wire [13:0] ada = {ADA13, ADA12, ADA11, ADA10, ADA9, ADA8, ADA7, ADA6, ADA5, ADA4, ADA3, ADA2, ADA1, ADA0};
  wire [13:0] adb = {ADB13, ADB12, ADB11, ADB10, ADB9, ADB8, ADB7, ADB6, ADB5, ADB4, ADB3, ADB2, ADB1, ADB0};
  wire selected_a = {CSA2, CSA1, CSA0} == 3'b000;
  wire selected_b = {CSB2, CSB1, CSB0} == 3'b000;

  reg [17:0] latch_a, latch_b, out_a, out_b;

  always @(posedge CLKA) begin
    if (CEA && selected_a) begin
      if (WEA) begin
        if (DATA_WIDTH_A == 9) words[ada[13:3]] <= dia[8:0];
        else begin
          if (ada[0]) words[{ada[13:4], 1'b0}] <= dia[8:0];
          if (ada[1]) words[{ada[13:4], 1'b1}] <= dia[17:9];
        end
      end else if (RSTA) latch_a <= 18'd0;
      else latch_a <= (DATA_WIDTH_A == 9) ? {9'd0, words[ada[13:3]]} : {words[{ada[13:4], 1'b1}], words[{ada[13:4], 1'b0}]};
    end
    if (RSTA) out_a <= 18'd0;
    else if (OCEA) out_a <= latch_a;
  end

  always @(posedge CLKB) begin
    if (CEB && selected_b) begin
      if (WEB) begin
        if (DATA_WIDTH_B == 9) words[adb[13:3]] <= dib[8:0];
        else begin
          if (adb[0]) words[{adb[13:4], 1'b0}] <= dib[8:0];
          if (adb[1]) words[{adb[13:4], 1'b1}] <= dib[17:9];
        end
      end else if (RSTB) latch_b <= 18'd0;
      else latch_b <= (DATA_WIDTH_B == 9) ? {9'd0, words[adb[13:3]]} : {words[{adb[13:4], 1'b1}], words[{adb[13:4], 1'b0}]};
    end
    if (RSTB) out_b <= 18'd0;
    else if (OCEB) out_b <= latch_b;
  end

  assign {DOA17, DOA16, DOA15, DOA14, DOA13, DOA12, DOA11, DOA10, DOA9, DOA8, DOA7, DOA6, DOA5, DOA4, DOA3, DOA2, DOA1, DOA0} =
    (REGMODE_A == "OUTREG") ? out_a : latch_a;
  assign {DOB17, DOB16, DOB15, DOB14, DOB13, DOB12, DOB11, DOB10, DOB9, DOB8, DOB7, DOB6, DOB5, DOB4, DOB3, DOB2, DOB1, DOB0} =
    (REGMODE_B == "OUTREG") ? out_b : latch_b;
endmodule
