// The cocotb testbench's top: the shell, with AXI protocol checkers on each of
// its interfaces and counters of the corner cases they saw (read by
// test_shell.py). Checked at every rising edge of aclk out of reset:
//  - a VALID the shell raises stays high, with the same payload, until READY
//    (m_axis, the write response, the read data); the testbench's sources
//    keep the same rule (s_axis);
//  - every output is 0 or 1, never X or Z;
//  - one write response per address and data taken, one read response per
//    read address taken, never before them;
//  - m_axis_tkeep is all ones.
// Each violation prints its cause and counts in `violations`.
`ifndef STREAM_BITS
`define STREAM_BITS 128
`endif
module bpaccel_shell_tb #(parameter W = `STREAM_BITS) (
  input              aclk,
  input              aresetn,
`ifdef DUAL_CLOCK
  input              core_clk,
`endif
  input  [W-1:0]     s_axis_tdata,
  input              s_axis_tvalid,
  output             s_axis_tready,
  input              s_axis_tlast,
  output [W-1:0]     m_axis_tdata,
  output             m_axis_tvalid,
  input              m_axis_tready,
  output             m_axis_tlast,
  output [W/8-1:0]   m_axis_tkeep,
  input  [11:0]      s_axil_awaddr,
  input              s_axil_awvalid,
  output             s_axil_awready,
  input  [31:0]      s_axil_wdata,
  input  [3:0]       s_axil_wstrb,
  input              s_axil_wvalid,
  output             s_axil_wready,
  output [1:0]       s_axil_bresp,
  output             s_axil_bvalid,
  input              s_axil_bready,
  input  [11:0]      s_axil_araddr,
  input              s_axil_arvalid,
  output             s_axil_arready,
  output [31:0]      s_axil_rdata,
  output [1:0]       s_axil_rresp,
  output             s_axil_rvalid,
  input              s_axil_rready,
  output             irq
);
  BpaccelShell shell (.*);

  integer violations = 0;
  // Set by the testbench while it resets its DMA channels and the shell (soft reset): both
  // streams may then drop TVALID, as at a reset.
  reg stream_reset = 0;
  // Corner cases seen: cycles of back-pressure on each stream and the write responses, rises of irq.
  integer input_stalls = 0, output_stalls = 0, response_stalls = 0, irq_rises = 0;

  reg m_held = 0, s_held = 0, b_held = 0, r_held = 0, irq_was = 0;
  reg [W:0] m_payload, s_payload;
  reg [1:0] b_payload;
  reg [33:0] r_payload;
  integer aw = 0, w = 0, b = 0, ar = 0, r = 0;

  task automatic violation(input [8*64-1:0] what);
    begin
      violations = violations + 1;
      $display("%0t ns: AXI protocol violation: %0s", $time, what);
    end
  endtask

  always @(posedge aclk) begin
    if (!aresetn) begin
      m_held <= 0; s_held <= 0; b_held <= 0; r_held <= 0;
      aw = 0; w = 0; b = 0; ar = 0; r = 0;
    end else begin
      if ((^{s_axis_tready, m_axis_tvalid, s_axil_awready, s_axil_wready, s_axil_bvalid, s_axil_arready,
             s_axil_rvalid, irq}) === 1'bx)
        violation("a handshake output or irq is X or Z");
      if (m_axis_tvalid && (^{m_axis_tlast, m_axis_tdata}) === 1'bx) violation("m_axis payload is X while valid");
      if (s_axil_bvalid && (^s_axil_bresp) === 1'bx) violation("BRESP is X while valid");
      if (s_axil_rvalid && (^{s_axil_rresp, s_axil_rdata}) === 1'bx) violation("RDATA or RRESP is X while valid");
      if (m_axis_tvalid && m_axis_tkeep != {W/8{1'b1}}) violation("m_axis_tkeep is not all ones");
      if (m_held && !stream_reset && (!m_axis_tvalid || {m_axis_tlast, m_axis_tdata} != m_payload)) violation("m_axis changed before TREADY");
      if (s_held && !stream_reset && (!s_axis_tvalid || {s_axis_tlast, s_axis_tdata} != s_payload)) violation("s_axis changed before TREADY");
      if (b_held && (!s_axil_bvalid || s_axil_bresp != b_payload)) violation("BVALID or BRESP changed before BREADY");
      if (r_held && (!s_axil_rvalid || {s_axil_rresp, s_axil_rdata} != r_payload)) violation("RVALID or RDATA changed before RREADY");
      m_held <= m_axis_tvalid && !m_axis_tready;  m_payload <= {m_axis_tlast, m_axis_tdata};
      s_held <= s_axis_tvalid && !s_axis_tready;  s_payload <= {s_axis_tlast, s_axis_tdata};
      b_held <= s_axil_bvalid && !s_axil_bready;  b_payload <= s_axil_bresp;
      r_held <= s_axil_rvalid && !s_axil_rready;  r_payload <= {s_axil_rresp, s_axil_rdata};
      aw = aw + (s_axil_awvalid && s_axil_awready);
      w = w + (s_axil_wvalid && s_axil_wready);
      ar = ar + (s_axil_arvalid && s_axil_arready);
      if (s_axil_bvalid && (b >= aw || b >= w)) violation("BVALID before its write address and data");
      if (s_axil_rvalid && r >= ar) violation("RVALID before its read address");
      b = b + (s_axil_bvalid && s_axil_bready);
      r = r + (s_axil_rvalid && s_axil_rready);
      input_stalls <= input_stalls + (s_axis_tvalid && !s_axis_tready);
      output_stalls <= output_stalls + (m_axis_tvalid && !m_axis_tready);
      response_stalls <= response_stalls + (s_axil_bvalid && !s_axil_bready);
      irq_rises <= irq_rises + (irq && !irq_was);
      irq_was <= irq;
    end
  end
endmodule
