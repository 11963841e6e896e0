// Reference DUT of the `slab` ray-box unit (raypipe HDL kit): a real pipeline, one register
// per stage of raypipe's slab stage table (stage 0: direction conversion, preparation and
// the three reciprocals; 1: six subtracts; 2: six multiplies; 3: near/far by the sign of
// 1/d; 4: the compare-select chains from tmin/tmax in axis order x, y, z; 5: widening by
// SLAB_WIDEN_ULPS grid steps; 6: hit = t_near <= t_far). Latency 7.
// The conversion, preparation and compare-select rules come from raypipe_box.sv.
// Every stage signal is carried to the end of the pipeline and presented on stg_row.
// Define RAYPIPE_INJECT_FAULT to make the tlox multiplier truncate instead of rounding to
// nearest (the kit's negative check: the testbench must fail, naming stage signal tlox).
// Bank faults (docs/faults.md) this DUT can carry, one define each (hdl/selftest checks that
// the testbench fails and that `raypipe faults` detects the same fault on the same set):
//   RAYPIPE_FAULT_SLAB_LOX_SWAP     slab.lox.swap: lo.x = o.x - min.x
//   RAYPIPE_FAULT_SLAB_NEGX_STUCK0  slab.negx.stuck0: the x near/far select tied to 0
//   RAYPIPE_FAULT_SLAB_HIT_STRICT   slab.hit.strict: t_near <= t_far tested as <
module raypipe_slab_ref
  import raypipe_fp::*;
  import raypipe_box::*;
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
  localparam int L = raypipe_set_pkg::LATENCY;

  typedef struct packed {
    slab_inputs_t i;
    slab_stages_t s;
  } state_t;

  // the tlox multiplier: the negative check's injected fault goes here
  function automatic word_t mul_tlox(word_t a, word_t b);
`ifdef RAYPIPE_INJECT_FAULT
    return fmul_faulty(F, a, b);
`else
    return fmul(F, a, b);
`endif
  endfunction

  // Table stage k - 1 applied to the state registered by stage k - 1.
  function automatic state_t stage(int k, state_t x);
    state_t y = x;
    case (k - 1)
      0: begin
        y.s.dx = conv(x.i.dx);
        y.s.dy = conv(x.i.dy);
        y.s.dz = conv(x.i.dz);
        y.i.ox = conv(x.i.ox);
        y.i.oy = conv(x.i.oy);
        y.i.oz = conv(x.i.oz);
        y.i.tmin = conv(x.i.tmin);
        y.i.tmax = conv(x.i.tmax);
        y.s.pdx = prep(y.s.dx);
        y.s.pdy = prep(y.s.dy);
        y.s.pdz = prep(y.s.dz);
        y.s.inv_dx = recip(y.s.pdx);
        y.s.inv_dy = recip(y.s.pdy);
        y.s.inv_dz = recip(y.s.pdz);
      end
      1: begin
`ifdef RAYPIPE_FAULT_SLAB_LOX_SWAP
        y.s.lox = gsub(x.i.ox, x.i.minx);
`else
        y.s.lox = gsub(x.i.minx, x.i.ox);
`endif
        y.s.hix = gsub(x.i.maxx, x.i.ox);
        y.s.loy = gsub(x.i.miny, x.i.oy);
        y.s.hiy = gsub(x.i.maxy, x.i.oy);
        y.s.loz = gsub(x.i.minz, x.i.oz);
        y.s.hiz = gsub(x.i.maxz, x.i.oz);
      end
      2: begin
        y.s.tlox = mul_tlox(x.s.lox, x.s.inv_dx);
        y.s.thix = fmul(F, x.s.hix, x.s.inv_dx);
        y.s.tloy = fmul(F, x.s.loy, x.s.inv_dy);
        y.s.thiy = fmul(F, x.s.hiy, x.s.inv_dy);
        y.s.tloz = fmul(F, x.s.loz, x.s.inv_dz);
        y.s.thiz = fmul(F, x.s.hiz, x.s.inv_dz);
      end
      3: begin
`ifdef RAYPIPE_FAULT_SLAB_NEGX_STUCK0
        y.s.negx = 1'b0;
`else
        y.s.negx = sign_of(F, x.s.inv_dx);
`endif
        y.s.negy = sign_of(F, x.s.inv_dy);
        y.s.negz = sign_of(F, x.s.inv_dz);
        y.s.nearx = y.s.negx ? x.s.thix : x.s.tlox;
        y.s.farx = y.s.negx ? x.s.tlox : x.s.thix;
        y.s.neary = y.s.negy ? x.s.thiy : x.s.tloy;
        y.s.fary = y.s.negy ? x.s.tloy : x.s.thiy;
        y.s.nearz = y.s.negz ? x.s.thiz : x.s.tloz;
        y.s.farz = y.s.negz ? x.s.tloz : x.s.thiz;
      end
      4: begin
        y.s.tn_x = near_sel(x.i.tmin, x.s.nearx);
        y.s.tn_xy = near_sel(y.s.tn_x, x.s.neary);
        y.s.tn_xyz = near_sel(y.s.tn_xy, x.s.nearz);
        y.s.tf_x = far_sel(x.i.tmax, x.s.farx);
        y.s.tf_xy = far_sel(y.s.tf_x, x.s.fary);
        y.s.tf_xyz = far_sel(y.s.tf_xy, x.s.farz);
      end
      5: begin
        y.s.t_near = widen(x.s.tn_xyz, 1'b0);
        y.s.t_far = widen(x.s.tf_xyz, 1'b1);
      end
`ifdef RAYPIPE_FAULT_SLAB_HIT_STRICT
      default: y.s.hit = flt(F, x.s.t_near, x.s.t_far);
`else
      default: y.s.hit = fle(F, x.s.t_near, x.s.t_far);
`endif
    endcase
    return y;
  endfunction

  // st[k] / v[k]: the state and valid bit after stage register k (0 = the input register);
  // one always_ff per register (Verilator 5.006 has no delayed assignment to arrays in loops),
  // and the last register a plain variable (Icarus 11 does not update continuous assigns from
  // array words written by a generate loop)
  state_t st [0:L-1];
  logic v [0:L-1];
  state_t last;
  always_ff @(posedge clk) begin
    v[0] <= rst_n & in_valid;
    st[0] <= {in_row, {$bits(slab_stages_t){1'b0}}};
  end
  for (genvar k = 1; k < L; k++) begin : g_stage
    always_ff @(posedge clk) begin
      v[k] <= rst_n & v[k-1];
      st[k] <= stage(k, st[k-1]);
    end
  end
  always_ff @(posedge clk) begin
    out_valid <= rst_n & v[L-1];
    last <= stage(L, st[L-1]);
  end

  slab_expected_t o;
  assign o.hit = last.s.hit;
  assign o.t_near = last.s.t_near;
  assign o.t_far = last.s.t_far;
  assign out_row = o;
  assign stg_row = last.s;
endmodule
