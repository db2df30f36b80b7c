// A self-checking smoke test of an emitted shell, for any simulator (FuseSoC's
// `sim` target): reads the identity and format registers, sends one CELLS
// command of two overlapping boxes, and checks the reply: one record naming
// the pair (0, 1), then a trailer without error. The full verification is the
// cocotb testbench (test/cocotb); this one proves the packaged files work.
`timescale 1ns / 1ps
module bpaccel_shell_smoke_tb #(parameter STREAM_BITS = 128);
  localparam K = STREAM_BITS / 32;
  reg aclk = 0, core_clk = 0, aresetn = 0;
  always #2 aclk = ~aclk;
  always #2.8 core_clk = ~core_clk;

  reg  [STREAM_BITS-1:0] s_tdata = 0;
  reg                    s_tvalid = 0, s_tlast = 0;
  wire                   s_tready;
  wire [STREAM_BITS-1:0] m_tdata;
  wire                   m_tvalid, m_tlast;
  wire [STREAM_BITS/8-1:0] m_tkeep;
  reg  [11:0] awaddr = 0, araddr = 0;
  reg         awvalid = 0, wvalid = 0, arvalid = 0;
  reg  [31:0] wdata = 0;
  wire        awready, wready, bvalid, arready, rvalid, irq;
  wire [1:0]  bresp, rresp;
  wire [31:0] rdata;

  BpaccelShell dut (
    .aclk(aclk), .aresetn(aresetn),
`ifdef DUAL_CLOCK
    .core_clk(core_clk),
`endif
    .s_axis_tdata(s_tdata), .s_axis_tvalid(s_tvalid), .s_axis_tready(s_tready), .s_axis_tlast(s_tlast),
    .m_axis_tdata(m_tdata), .m_axis_tvalid(m_tvalid), .m_axis_tready(1'b1), .m_axis_tlast(m_tlast), .m_axis_tkeep(m_tkeep),
    .s_axil_awaddr(awaddr), .s_axil_awvalid(awvalid), .s_axil_awready(awready), .s_axil_wdata(wdata),
    .s_axil_wstrb(4'hF), .s_axil_wvalid(wvalid), .s_axil_wready(wready), .s_axil_bresp(bresp),
    .s_axil_bvalid(bvalid), .s_axil_bready(1'b1), .s_axil_araddr(araddr), .s_axil_arvalid(arvalid),
    .s_axil_arready(arready), .s_axil_rdata(rdata), .s_axil_rresp(rresp), .s_axil_rvalid(rvalid),
    .s_axil_rready(1'b1), .irq(irq));

  task automatic fail(input [8*48-1:0] what);
    begin $display("FAIL: %0s", what); $fatal(1); end
  endtask

  task automatic read(input [11:0] addr, output [31:0] value);
    begin
      @(negedge aclk) araddr = addr; arvalid = 1;
      @(posedge aclk) while (!arready) @(posedge aclk);
      @(negedge aclk) arvalid = 0;
      while (!rvalid) @(posedge aclk);
      value = rdata;
      @(posedge aclk);
    end
  endtask

  // The command's words: header, one cell, its header {2, 0}, two boxes (six keys each, or three words at 16 bits).
  reg [31:0] words [0:63];
  integer n = 0, i, box_words, record_words, index_width, beat, received = 0;
  reg [31:0] value, i_base, j_base, mask, reply [0:255];
  integer lane;

  task automatic put(input [31:0] w); begin words[n] = w; n = n + 1; end endtask
  task automatic put_box(input [15:0] lo, input [15:0] hi);
    begin
      if (box_words == 6) begin put(lo); put(lo); put(lo); put(hi); put(hi); put(hi); end
      else begin put({lo, lo}); put({hi, lo}); put({hi, hi}); end
    end
  endtask

  always @(posedge aclk) if (m_tvalid) begin
    for (i = 0; i < K; i = i + 1) reply[received + i] <= m_tdata[32*i +: 32];
    received <= received + K;
  end

  initial begin
    repeat (5) @(posedge aclk);
    aresetn = 1;
    read(12'h104, value); while (!value[0]) read(12'h104, value);        // STATUS.READY
    read(12'h000, value); if (value != 32'h43415042) fail("ID is not BPAC");
    read(12'h03C, value); box_words = value[7:0]; record_words = value[15:8];
    read(12'h024, value); index_width = value;
    put(32'h0102); put(1); put(2); put(0); put_box(16'd1, 16'd5); put_box(16'd4, 16'd9);
    while (n % K) put(0);
    for (beat = 0; beat < n / K; beat = beat + 1) begin
      @(negedge aclk);
      for (i = 0; i < K; i = i + 1) s_tdata[32*i +: 32] = words[beat * K + i];
      s_tvalid = 1; s_tlast = (beat == n / K - 1);
      @(posedge aclk) while (!s_tready) @(posedge aclk);
    end
    @(negedge aclk) s_tvalid = 0;
    wait (m_tvalid && m_tlast); @(posedge aclk); @(posedge aclk);
    // The trailer is the last 16 words; the record precedes it.
    if (reply[received - 16][31:24] != 8'hB7) fail("no trailer magic");
    if (reply[received - 16][15:8] != 0) fail("the command failed");
    if (reply[received - 14] != 1) fail("not one record");
    if (reply[received - 6] != 1) fail("not one pair");
    if (index_width <= 16) begin i_base = reply[0][15:0]; j_base = reply[0][31:16]; value = reply[1]; mask = reply[2]; end
    else begin i_base = reply[0]; j_base = reply[1]; value = reply[2]; mask = reply[3]; end
    if (value != 0) fail("the record's cell is not 0");
    lane = 0; while (lane < 32 && !mask[lane]) lane = lane + 1;
    if (lane == 32 || mask != (32'h1 << lane)) fail("the record's mask is not one lane");
    if ((((i_base + lane) & ((1 << index_width) - 1)) != 0) || (((j_base + lane) & ((1 << index_width) - 1)) != 1))
      fail("the record is not the pair (0, 1)");
    $display("PASS: bpaccel shell smoke test (%0d-bit stream, %0d-word records)", STREAM_BITS, record_words);
    $finish;
  end
endmodule
