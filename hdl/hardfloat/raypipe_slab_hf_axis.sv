// The HardFloat slab datapath as raypipe_rti_hf_axis.sv builds the rti one (that file says how):
// AXI4-Stream ports, the documented default tdata layout written by hand, stage probes on
// m_axis_tuser, the core behind raypipe_stream_fifo.
//   slab  s_axis_tdata: ox oy oz dx dy dz tmin tmax minx miny minz maxx maxy maxz
//         m_axis_tdata: hit (bit 0) t_near t_far
module raypipe_slab_hf_axis
  import raypipe_set_pkg::*;
  import raypipe_slab_pkg::*;
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
  input  logic [((14 * int'(WIDTH) + 7) / 8) * 8 - 1:0] s_axis_tdata,
  input  logic [IDW-1:0] s_axis_tid,
  output logic m_axis_tvalid,
  input  logic m_axis_tready,
  output logic [((1 + 2 * int'(WIDTH) + 7) / 8) * 8 - 1:0] m_axis_tdata,
  output logic [STG_W-1:0] m_axis_tuser,
  output logic [IDW-1:0] m_axis_tid
);
  localparam int W = int'(WIDTH);
  localparam int MW = ((1 + 2 * W + 7) / 8) * 8;
  logic [IN_W-1:0] row;
  always @* begin
    row = '0;
    for (int k = 0; k < 14; k++) row[(13 - k) * W +: W] = s_axis_tdata[k * W +: W];
  end
  logic take, core_valid;
  slab_expected_t core_out, out;
  logic [STG_W-1:0] core_stg;
  raypipe_slab_hf core (.clk(aclk), .rst_n(aresetn), .in_valid(take), .in_row(row), .out_valid(core_valid),
                        .out_row(core_out), .stg_row(core_stg));
  raypipe_stream_fifo #(.W(OUT_W + STG_W), .IDW(IDW), .DEPTH(DEPTH)) fifo (
    .clk(aclk), .rst_n(aresetn), .in_valid(s_axis_tvalid), .in_ready(s_axis_tready), .in_id(s_axis_tid),
    .take(take), .core_valid(core_valid), .core_data({core_out, core_stg}), .out_valid(m_axis_tvalid),
    .out_ready(m_axis_tready), .out_data({out, m_axis_tuser}), .out_id(m_axis_tid));
  assign m_axis_tdata = MW'({out.t_far, out.t_near, out.hit});
endmodule
