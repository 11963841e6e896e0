// Worked example: hooking your own slab RTL into the raypipe HDL kit.
//
// Your core has its own port names, no probe outputs and, say, three more register stages
// than raypipe's stage table (latency 7 + 3 = 10). The wrapper maps the kit's rows onto your
// ports: the input row is unpacked through the generated struct raypipe_slab_pkg::slab_inputs_t,
// your results are packed into slab_expected_t, and stg_row is tied to zero (run +nostages).
// Here the "core" is the reference DUT followed by three registers, standing in for yours.
//
//   raypipe vectors --unit slab --format f32 --variant conservative --out set
//   hdl/run --dut my_slab_wrapper --rtl hdl/sv/ref/slab_ref.sv --rtl hdl/examples/my_slab_wrapper.sv \
//     set +nostages +latency=10
// (the first --rtl is the stand-in core; list your own sources instead)
module my_slab_wrapper
  import raypipe_set_pkg::*;
  import raypipe_slab_pkg::*;
(
  input  logic             clk,
  input  logic             rst_n,
  input  logic             in_valid,
  input  logic [IN_W-1:0]  in_row,
  output logic             out_valid,
  output logic [OUT_W-1:0] out_row,
  output logic [STG_W-1:0] stg_row
);
  slab_inputs_t i;
  assign i = in_row;

  // --- your core: replace this block with your module, wired field by field ---
  logic core_valid;
  logic core_hit;
  logic [WIDTH-1:0] core_t_near, core_t_far;
  logic [OUT_W-1:0] ref_out;
  logic [STG_W-1:0] unused_probes;
  raypipe_slab_ref reference (
    .clk(clk), .rst_n(rst_n), .in_valid(in_valid),
    .in_row({i.class_id, i.ox, i.oy, i.oz, i.dx, i.dy, i.dz, i.tmin, i.tmax,
             i.minx, i.miny, i.minz, i.maxx, i.maxy, i.maxz}),
    .out_valid(core_valid), .out_row(ref_out), .stg_row(unused_probes));
  logic [2:0] v_pipe;
  logic [OUT_W-1:0] o_pipe [0:2];
  always_ff @(posedge clk) begin
    v_pipe <= {v_pipe[1:0], rst_n & core_valid};
    o_pipe[0] <= ref_out;
    o_pipe[1] <= o_pipe[0];
    o_pipe[2] <= o_pipe[1];
  end
  slab_expected_t r;
  assign r = o_pipe[2];
  assign core_hit = r.hit;
  assign core_t_near = r.t_near;
  assign core_t_far = r.t_far;
  // --- end of your core ---

  slab_expected_t o;
  assign o.hit = core_hit;
  assign o.t_near = core_t_near;
  assign o.t_far = core_t_far;
  assign out_row = o;
  assign out_valid = v_pipe[2];
  assign stg_row = '0;
endmodule
