// Reference DUT of the `rti` ray-triangle unit (raypipe HDL kit): a real pipeline, one
// register per stage of raypipe's latency-reordered Moller-Trumbore stage table
// (1: nine subtracts; 2: twelve products; 3: six cross-product subtracts; 4: twelve
// dot-product multiplies; 5, 6: the two adds of each dot product; 7: u'+v' and the
// division-free validity test; then the division: recip-mul formats 8: 1/det, 9: t, u, v
// products, 10: the t-interval test; divide formats 8: three divides, 9: the t-interval test).
// Every stage signal is carried to the end of the pipeline and presented on stg_row.
// Define RAYPIPE_SKIP_DIVIDE to zero the divide's signals when valid = 0 (a DUT that skips the
// divide; the testbench must still pass). Define RAYPIPE_INJECT_FAULT to make the detx multiplier truncate instead of rounding to
// nearest (the kit's negative check: the testbench must fail, naming stage signal detx).
// Bank faults (docs/faults.md) this DUT can carry, one define each (hdl/selftest checks that
// the testbench fails and that `raypipe faults` detects the same fault on the same set):
//   RAYPIPE_FAULT_RTI_E1X_SWAP      rti.e1x.swap: e1.x = v0.x - v1.x
//   RAYPIPE_FAULT_RTI_UV_OK_STRICT  rti.uv_ok.strict: u' + v' <= det tested as <
//   RAYPIPE_FAULT_RTI_T_OK_STUCK1   rti.t_ok.stuck1: the t' >= 0 check left out
module raypipe_rti_ref
  import raypipe_fp::*;
  import raypipe_set_pkg::*;
  import raypipe_rti_pkg::*;
(
  input  logic             clk,
  input  logic             rst_n,
  input  logic             in_valid,
  input  logic [IN_W-1:0]  in_row,
  output logic             out_valid,
  output logic [OUT_W-1:0] out_row,
  output logic [STG_W-1:0] stg_row
);
  localparam logic [$bits(fmt_t)-1:0] F = {EXP[7:0], MAN[7:0], FTZ[0], NAN_PROPAGATE[0]};  // an fmt_t
  localparam int L = raypipe_set_pkg::LATENCY;

  typedef struct packed {
    rti_inputs_t i;
    rti_stages_t s;
  } state_t;

  function automatic word_t mul(word_t a, word_t b);
    return fmul(F, a, b);
  endfunction

  // the detx multiplier: the negative check's injected fault goes here
  function automatic word_t mul_detx(word_t a, word_t b);
`ifdef RAYPIPE_INJECT_FAULT
    return fmul_faulty(F, a, b);
`else
    return fmul(F, a, b);
`endif
  endfunction

  // det > 0 ? lo <= hi : hi <= lo, the sign-dependent compare of stage 7
  function automatic logic between(logic pos, word_t lo, word_t hi);
    return pos ? fle(F, lo, hi) : fle(F, hi, lo);
  endfunction

  // Table stage k applied to the state registered by stage k - 1.
  function automatic state_t stage(int k, state_t x);
    state_t y = x;
    logic pos;
    case (k)
      1: begin
`ifdef RAYPIPE_FAULT_RTI_E1X_SWAP
        y.s.e1x = fsub(F, x.i.v0x, x.i.v1x);
`else
        y.s.e1x = fsub(F, x.i.v1x, x.i.v0x);
`endif
        y.s.e1y = fsub(F, x.i.v1y, x.i.v0y);
        y.s.e1z = fsub(F, x.i.v1z, x.i.v0z);
        y.s.e2x = fsub(F, x.i.v2x, x.i.v0x);
        y.s.e2y = fsub(F, x.i.v2y, x.i.v0y);
        y.s.e2z = fsub(F, x.i.v2z, x.i.v0z);
        y.s.sx = fsub(F, x.i.ox, x.i.v0x);
        y.s.sy = fsub(F, x.i.oy, x.i.v0y);
        y.s.sz = fsub(F, x.i.oz, x.i.v0z);
      end
      2: begin
        y.s.pxa = mul(x.i.dy, x.s.e2z);
        y.s.pxb = mul(x.i.dz, x.s.e2y);
        y.s.pya = mul(x.i.dz, x.s.e2x);
        y.s.pyb = mul(x.i.dx, x.s.e2z);
        y.s.pza = mul(x.i.dx, x.s.e2y);
        y.s.pzb = mul(x.i.dy, x.s.e2x);
        y.s.qxa = mul(x.s.sy, x.s.e1z);
        y.s.qxb = mul(x.s.sz, x.s.e1y);
        y.s.qya = mul(x.s.sz, x.s.e1x);
        y.s.qyb = mul(x.s.sx, x.s.e1z);
        y.s.qza = mul(x.s.sx, x.s.e1y);
        y.s.qzb = mul(x.s.sy, x.s.e1x);
      end
      3: begin
        y.s.px = fsub(F, x.s.pxa, x.s.pxb);
        y.s.py = fsub(F, x.s.pya, x.s.pyb);
        y.s.pz = fsub(F, x.s.pza, x.s.pzb);
        y.s.qx = fsub(F, x.s.qxa, x.s.qxb);
        y.s.qy = fsub(F, x.s.qya, x.s.qyb);
        y.s.qz = fsub(F, x.s.qza, x.s.qzb);
      end
      4: begin
        y.s.detx = mul_detx(x.s.e1x, x.s.px);
        y.s.dety = mul(x.s.e1y, x.s.py);
        y.s.detz = mul(x.s.e1z, x.s.pz);
        y.s.upx = mul(x.s.sx, x.s.px);
        y.s.upy = mul(x.s.sy, x.s.py);
        y.s.upz = mul(x.s.sz, x.s.pz);
        y.s.vpx = mul(x.i.dx, x.s.qx);
        y.s.vpy = mul(x.i.dy, x.s.qy);
        y.s.vpz = mul(x.i.dz, x.s.qz);
        y.s.tpx = mul(x.s.e2x, x.s.qx);
        y.s.tpy = mul(x.s.e2y, x.s.qy);
        y.s.tpz = mul(x.s.e2z, x.s.qz);
      end
      5: begin
        y.s.det_xy = fadd(F, x.s.detx, x.s.dety);
        y.s.up_xy = fadd(F, x.s.upx, x.s.upy);
        y.s.vp_xy = fadd(F, x.s.vpx, x.s.vpy);
        y.s.tp_xy = fadd(F, x.s.tpx, x.s.tpy);
      end
      6: begin
        y.s.det = fadd(F, x.s.det_xy, x.s.detz);
        y.s.up = fadd(F, x.s.up_xy, x.s.upz);
        y.s.vp = fadd(F, x.s.vp_xy, x.s.vpz);
        y.s.tp = fadd(F, x.s.tp_xy, x.s.tpz);
      end
      7: begin
        y.s.uv = fadd(F, x.s.up, x.s.vp);
        y.s.det_ok = CULL_BACKFACE[0] ? flt(F, DET_THR, x.s.det) : flt(F, DET_THR, fabs(F, x.s.det));
        pos = flt(F, zero_of(F, 1'b0), x.s.det);
        y.s.u_ok = between(pos, zero_of(F, 1'b0), x.s.up);
        y.s.v_ok = between(pos, zero_of(F, 1'b0), x.s.vp);
        y.s.uv_ok = between(pos, y.s.uv, x.s.det);
`ifdef RAYPIPE_FAULT_RTI_UV_OK_STRICT
        y.s.uv_ok = pos ? flt(F, y.s.uv, x.s.det) : flt(F, x.s.det, y.s.uv);
`endif
        y.s.t_ok = between(pos, zero_of(F, 1'b0), x.s.tp);
`ifdef RAYPIPE_FAULT_RTI_T_OK_STUCK1
        y.s.t_ok = 1'b1;
`endif
        y.s.valid = y.s.det_ok & y.s.u_ok & y.s.v_ok & y.s.uv_ok & y.s.t_ok;
      end
`ifdef RAYPIPE_RECIP_MUL
      8: y.s.inv_det = fdiv(F, one_of(F), x.s.det);
      9: begin
        y.s.t = mul(x.s.tp, x.s.inv_det);
        y.s.u = mul(x.s.up, x.s.inv_det);
        y.s.v = mul(x.s.vp, x.s.inv_det);
      end
`else
      8: begin
        y.s.t = fdiv(F, x.s.tp, x.s.det);
        y.s.u = fdiv(F, x.s.up, x.s.det);
        y.s.v = fdiv(F, x.s.vp, x.s.det);
      end
`endif
      default: begin
        y.s.tmin_ok = fle(F, x.i.tmin, x.s.t);
        y.s.tmax_ok = fle(F, x.s.t, x.i.tmax);
        y.s.hit = x.s.valid & y.s.tmin_ok & y.s.tmax_ok;
      end
    endcase
`ifdef RAYPIPE_SKIP_DIVIDE
    // a thesis-style DUT: once the valid bit clears, the divide stage is skipped and everything
    // after it reads 0 (the manifest marks those fields care_when valid: the set must pass)
    if (k > 7 && !y.s.valid) begin
`ifdef RAYPIPE_RECIP_MUL
      y.s.inv_det = '0;
`endif
      y.s.t = '0;
      y.s.u = '0;
      y.s.v = '0;
      y.s.tmin_ok = 1'b0;
      y.s.tmax_ok = 1'b0;
    end
`endif
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
    st[0] <= {in_row, {$bits(rti_stages_t){1'b0}}};
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

  rti_expected_t o;
  assign o.valid = last.s.valid;
  assign o.hit = last.s.hit;
  assign o.t = last.s.t;
  assign o.u = last.s.u;
  assign o.v = last.s.v;
  assign out_row = o;
  assign stg_row = last.s;
endmodule
