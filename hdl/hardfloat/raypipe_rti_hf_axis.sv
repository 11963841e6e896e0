// The HardFloat rti datapath (raypipe_rti_hf) as a user would ship it (raypipe_slab_hf_axis.sv:
// the slab unit alike): AXI4-Stream ports, valid/ready on both sides, the stage probes on m_axis_tuser. The
// tdata layouts are written here by hand from docs/your-dut.md's default map (each field W =
// 1 + EXP + MAN bits wide, the first field at bit 0, the next above it, widths rounded up to
// whole bytes), not from the generated wrapper, so a run through raypipe_axis_wrap.sv checks
// the generated packing against this independent reading of the documented order:
//   rti   s_axis_tdata: ox oy oz dx dy dz tmin tmax v0x v0y v0z v1x v1y v1z v2x v2y v2z
//         m_axis_tdata: valid (bit 0) hit (bit 1) t u v
// m_axis_tuser is the stage row as the set's stage file lays it out. The fixed-latency core
// sits behind raypipe_stream_fifo (hdl/sv/raypipe_stream.sv): one test per clock while
// m_axis_tready is 1, results in input order; s_axis_tid comes back on m_axis_tid (IDW bits).
// RAYPIPE_STREAM_SWAP: the FIFO lets each two consecutive results leave swapped, ids and all — a
// test that a testbench matches out-of-order results by id.
module raypipe_rti_hf_axis
  import raypipe_set_pkg::*;
  import raypipe_rti_pkg::*;
#(
`ifdef RAYPIPE_ID_W
  parameter int IDW = `RAYPIPE_ID_W,
`else
  parameter int IDW = 1,
`endif
  parameter int DEPTH = 64
) (
  input  logic aclk,
  input  logic aresetn,
  input  logic s_axis_tvalid,
  output logic s_axis_tready,
  input  logic [((17 * int'(WIDTH) + 7) / 8) * 8 - 1:0] s_axis_tdata,
  input  logic [IDW-1:0] s_axis_tid,
  output logic m_axis_tvalid,
  input  logic m_axis_tready,
  output logic [((2 + 3 * int'(WIDTH) + 7) / 8) * 8 - 1:0] m_axis_tdata,
  output logic [STG_W-1:0] m_axis_tuser,
  output logic [IDW-1:0] m_axis_tid
);
  localparam int W = int'(WIDTH);
  localparam int MW = ((2 + 3 * W + 7) / 8) * 8;
  logic [IN_W-1:0] row;
  always @* begin
    row = '0;  // the class tag (the row's top 8 bits) is the testbench's, not the DUT's
    for (int k = 0; k < 17; k++) row[(16 - k) * W +: W] = s_axis_tdata[k * W +: W];
  end
  logic take, core_valid;
  rti_expected_t core_out, out;
  logic [STG_W-1:0] core_stg;
  raypipe_rti_hf core (.clk(aclk), .rst_n(aresetn), .in_valid(take), .in_row(row), .out_valid(core_valid),
                       .out_row(core_out), .stg_row(core_stg));
  raypipe_stream_fifo #(.W(OUT_W + STG_W), .IDW(IDW), .DEPTH(DEPTH)) fifo (
    .clk(aclk), .rst_n(aresetn), .in_valid(s_axis_tvalid), .in_ready(s_axis_tready), .in_id(s_axis_tid),
    .take(take), .core_valid(core_valid), .core_data({core_out, core_stg}), .out_valid(m_axis_tvalid),
    .out_ready(m_axis_tready), .out_data({out, m_axis_tuser}), .out_id(m_axis_tid));
  assign m_axis_tdata = MW'({out.v, out.u, out.t, out.hit, out.valid});
endmodule

