// The `rti` ray-triangle unit assembled from Berkeley HardFloat units (raypipe_hf_ops.sv): the
// latency-reordered Moller-Trumbore stage table of raypipe (1: nine subtracts; 2: twelve
// products; 3: six subtracts; 4: twelve products; 5, 6: the two adds of each dot product;
// 7: u'+v' and the division-free validity test; recip-mul sets 8: 1/det, 9: the t, u, v
// products, 10: the t-interval test; divide sets 8: three divides, 9: the t-interval test).
// One register per table stage, except the division stage, which takes N + 1 clock edges, N =
// S + 2 (raypipe_hf_divbank: N dividers in turn take the operands at one edge and their result
// is registered N edges later; one test per clock): latency = the set's LATENCY + S + 2. Same ports as the kit's reference DUTs; every stage signal on stg_row.
//
// The format comes from the set (raypipe_set_pkg): E = EXP, S = MAN + 1. HardFloat's RISCV
// specialisation computes raypipe's `ieee` + `canonical` options (no flush-to-zero, NaN results
// the canonical NaN); a set with `ftz` or `propagate` is refused at elaboration.
// Faults (one define each; hdl/hardfloat/README.md):
//   RAYPIPE_HF_FAULT_E1X_SWAP    e1.x = v0.x - v1.x (operand swap)
//   RAYPIPE_HF_FAULT_UV_STRICT   u' + v' <= det tested as < (strict compare)
//   RAYPIPE_HF_FAULT_DETX_RNA    the det.x multiplier's roundingMode port tied to 100 (nearest, ties
//                                away from zero: round_near_maxMag)
//   RAYPIPE_HF_FAULT_QX_FTZ      a flush-to-zero wrapper on stage 3's q.x (subnormal -> 0 of its sign)
// Each is the bank fault of the same name in raypipe's fault model (rti.e1x.swap,
// rti.uv_ok.strict, rti.detx.rna, rti.qx.ftz): hdl/hardfloat/selftest checks that the RTL fails
// first at the vector where `raypipe faults` first detects the modelled fault.
module raypipe_rti_hf
  import raypipe_set_pkg::*;
  import raypipe_rti_pkg::*;
#(
  parameter int E = int'(EXP),
  parameter int S = int'(MAN) + 1
) (
  input  logic             clk,
  input  logic             rst_n,
  input  logic             in_valid,
  input  logic [IN_W-1:0]  in_row,
  output logic             out_valid,
  output logic [OUT_W-1:0] out_row,
  output logic [STG_W-1:0] stg_row
);
  localparam int W = E + S;
  localparam int ND = S + 2;  // edges of the division stage
  localparam logic [2:0] RNE = 3'b000;
  localparam logic [W-1:0] ZERO = '0;
  localparam logic [W-1:0] ONE = W'(((1 << (E - 1)) - 1)) << (S - 1);
  localparam logic [W-1:0] THR = DET_THR[W-1:0];
`ifdef RAYPIPE_RECIP_MUL
  localparam bit RECIP = 1;
`else
  localparam bit RECIP = 0;
`endif
  // the stage after which the division's N - 1 extra registers sit (7), and the last table stage
  localparam int LAST = RECIP ? 10 : 9;

  initial begin
    if (FTZ != 0 || NAN_PROPAGATE != 0)
      $fatal(1, "raypipe_rti_hf: HardFloat (RISCV) computes the ieee+canonical options; this set has ftz=%0d propagate=%0d",
             FTZ, NAN_PROPAGATE);
    if (E + S != int'(WIDTH)) $fatal(1, "raypipe_rti_hf: the set's fields are not %0d bits", E + S);
  end

  typedef struct packed {
    rti_inputs_t i;
    rti_stages_t s;
  } state_t;

  // r[k]: the state after table stage k (r[0]: the input register); vk its valid bit
  state_t r0, r1, r2, r3, r4, r5, r6, r7, r8, r9, r10;
  logic v0, v1, v2, v3, v4, v5, v6, v7, v8, v9, v10;
  state_t n1, n2, n3, n4, n5, n6, n7, n8, n9, n10;

  // ---- stage 1: e1 = v1 - v0, e2 = v2 - v0, s = o - v0
  wire [W-1:0] e1x, e1y, e1z, e2x, e2y, e2z, sx, sy, sz;
`ifdef RAYPIPE_HF_FAULT_E1X_SWAP
  raypipe_hf_add #(E, S) u_e1x (.a(r0.i.v0x), .b(r0.i.v1x), .sub(1'b1), .rm(RNE), .y(e1x));
`else
  raypipe_hf_add #(E, S) u_e1x (.a(r0.i.v1x), .b(r0.i.v0x), .sub(1'b1), .rm(RNE), .y(e1x));
`endif
  raypipe_hf_add #(E, S) u_e1y (.a(r0.i.v1y), .b(r0.i.v0y), .sub(1'b1), .rm(RNE), .y(e1y));
  raypipe_hf_add #(E, S) u_e1z (.a(r0.i.v1z), .b(r0.i.v0z), .sub(1'b1), .rm(RNE), .y(e1z));
  raypipe_hf_add #(E, S) u_e2x (.a(r0.i.v2x), .b(r0.i.v0x), .sub(1'b1), .rm(RNE), .y(e2x));
  raypipe_hf_add #(E, S) u_e2y (.a(r0.i.v2y), .b(r0.i.v0y), .sub(1'b1), .rm(RNE), .y(e2y));
  raypipe_hf_add #(E, S) u_e2z (.a(r0.i.v2z), .b(r0.i.v0z), .sub(1'b1), .rm(RNE), .y(e2z));
  raypipe_hf_add #(E, S) u_sx (.a(r0.i.ox), .b(r0.i.v0x), .sub(1'b1), .rm(RNE), .y(sx));
  raypipe_hf_add #(E, S) u_sy (.a(r0.i.oy), .b(r0.i.v0y), .sub(1'b1), .rm(RNE), .y(sy));
  raypipe_hf_add #(E, S) u_sz (.a(r0.i.oz), .b(r0.i.v0z), .sub(1'b1), .rm(RNE), .y(sz));
  always @* begin
    n1 = r0;
    {n1.s.e1x, n1.s.e1y, n1.s.e1z, n1.s.e2x, n1.s.e2y, n1.s.e2z} = {e1x, e1y, e1z, e2x, e2y, e2z};
    {n1.s.sx, n1.s.sy, n1.s.sz} = {sx, sy, sz};
  end

  // ---- stage 2: the twelve products of p = d x e2 and q = s x e1
  wire [W-1:0] pxa, pxb, pya, pyb, pza, pzb, qxa, qxb, qya, qyb, qza, qzb;
  raypipe_hf_mul #(E, S) u_pxa (.a(r1.i.dy), .b(r1.s.e2z), .rm(RNE), .y(pxa));
  raypipe_hf_mul #(E, S) u_pxb (.a(r1.i.dz), .b(r1.s.e2y), .rm(RNE), .y(pxb));
  raypipe_hf_mul #(E, S) u_pya (.a(r1.i.dz), .b(r1.s.e2x), .rm(RNE), .y(pya));
  raypipe_hf_mul #(E, S) u_pyb (.a(r1.i.dx), .b(r1.s.e2z), .rm(RNE), .y(pyb));
  raypipe_hf_mul #(E, S) u_pza (.a(r1.i.dx), .b(r1.s.e2y), .rm(RNE), .y(pza));
  raypipe_hf_mul #(E, S) u_pzb (.a(r1.i.dy), .b(r1.s.e2x), .rm(RNE), .y(pzb));
  raypipe_hf_mul #(E, S) u_qxa (.a(r1.s.sy), .b(r1.s.e1z), .rm(RNE), .y(qxa));
  raypipe_hf_mul #(E, S) u_qxb (.a(r1.s.sz), .b(r1.s.e1y), .rm(RNE), .y(qxb));
  raypipe_hf_mul #(E, S) u_qya (.a(r1.s.sz), .b(r1.s.e1x), .rm(RNE), .y(qya));
  raypipe_hf_mul #(E, S) u_qyb (.a(r1.s.sx), .b(r1.s.e1z), .rm(RNE), .y(qyb));
  raypipe_hf_mul #(E, S) u_qza (.a(r1.s.sx), .b(r1.s.e1y), .rm(RNE), .y(qza));
  raypipe_hf_mul #(E, S) u_qzb (.a(r1.s.sy), .b(r1.s.e1x), .rm(RNE), .y(qzb));
  always @* begin
    n2 = r1;
    {n2.s.pxa, n2.s.pxb, n2.s.pya, n2.s.pyb, n2.s.pza, n2.s.pzb} = {pxa, pxb, pya, pyb, pza, pzb};
    {n2.s.qxa, n2.s.qxb, n2.s.qya, n2.s.qyb, n2.s.qza, n2.s.qzb} = {qxa, qxb, qya, qyb, qza, qzb};
  end

  // ---- stage 3: the cross products' subtracts
  wire [W-1:0] px, py, pz, qx, qy, qz;
  raypipe_hf_add #(E, S) u_px (.a(r2.s.pxa), .b(r2.s.pxb), .sub(1'b1), .rm(RNE), .y(px));
  raypipe_hf_add #(E, S) u_py (.a(r2.s.pya), .b(r2.s.pyb), .sub(1'b1), .rm(RNE), .y(py));
  raypipe_hf_add #(E, S) u_pz (.a(r2.s.pza), .b(r2.s.pzb), .sub(1'b1), .rm(RNE), .y(pz));
  raypipe_hf_add #(E, S) u_qx (.a(r2.s.qxa), .b(r2.s.qxb), .sub(1'b1), .rm(RNE), .y(qx));
  raypipe_hf_add #(E, S) u_qy (.a(r2.s.qya), .b(r2.s.qyb), .sub(1'b1), .rm(RNE), .y(qy));
  raypipe_hf_add #(E, S) u_qz (.a(r2.s.qza), .b(r2.s.qzb), .sub(1'b1), .rm(RNE), .y(qz));
  always @* begin
    n3 = r2;
    {n3.s.px, n3.s.py, n3.s.pz, n3.s.qx, n3.s.qy, n3.s.qz} = {px, py, pz, qx, qy, qz};
`ifdef RAYPIPE_HF_FAULT_QX_FTZ
    // a flush-to-zero wrapper on q.x: a subnormal becomes zero of its sign
    if (qx[W-2:S-1] == 0) n3.s.qx = {qx[W-1], {(W - 1) {1'b0}}};
`endif
  end

  // ---- stage 4: the dot products' multiplies (det = e1.p, u' = s.p, v' = d.q, t' = e2.q)
  wire [W-1:0] detx, dety, detz, upx, upy, upz, vpx, vpy, vpz, tpx, tpy, tpz;
`ifdef RAYPIPE_HF_FAULT_DETX_RNA
  raypipe_hf_mul #(E, S) u_detx (.a(r3.s.e1x), .b(r3.s.px), .rm(3'b100), .y(detx));
`else
  raypipe_hf_mul #(E, S) u_detx (.a(r3.s.e1x), .b(r3.s.px), .rm(RNE), .y(detx));
`endif
  raypipe_hf_mul #(E, S) u_dety (.a(r3.s.e1y), .b(r3.s.py), .rm(RNE), .y(dety));
  raypipe_hf_mul #(E, S) u_detz (.a(r3.s.e1z), .b(r3.s.pz), .rm(RNE), .y(detz));
  raypipe_hf_mul #(E, S) u_upx (.a(r3.s.sx), .b(r3.s.px), .rm(RNE), .y(upx));
  raypipe_hf_mul #(E, S) u_upy (.a(r3.s.sy), .b(r3.s.py), .rm(RNE), .y(upy));
  raypipe_hf_mul #(E, S) u_upz (.a(r3.s.sz), .b(r3.s.pz), .rm(RNE), .y(upz));
  raypipe_hf_mul #(E, S) u_vpx (.a(r3.i.dx), .b(r3.s.qx), .rm(RNE), .y(vpx));
  raypipe_hf_mul #(E, S) u_vpy (.a(r3.i.dy), .b(r3.s.qy), .rm(RNE), .y(vpy));
  raypipe_hf_mul #(E, S) u_vpz (.a(r3.i.dz), .b(r3.s.qz), .rm(RNE), .y(vpz));
  raypipe_hf_mul #(E, S) u_tpx (.a(r3.s.e2x), .b(r3.s.qx), .rm(RNE), .y(tpx));
  raypipe_hf_mul #(E, S) u_tpy (.a(r3.s.e2y), .b(r3.s.qy), .rm(RNE), .y(tpy));
  raypipe_hf_mul #(E, S) u_tpz (.a(r3.s.e2z), .b(r3.s.qz), .rm(RNE), .y(tpz));
  always @* begin
    n4 = r3;
    {n4.s.detx, n4.s.dety, n4.s.detz, n4.s.upx, n4.s.upy, n4.s.upz} = {detx, dety, detz, upx, upy, upz};
    {n4.s.vpx, n4.s.vpy, n4.s.vpz, n4.s.tpx, n4.s.tpy, n4.s.tpz} = {vpx, vpy, vpz, tpx, tpy, tpz};
  end

  // ---- stage 5: x + y of each dot product
  wire [W-1:0] det_xy, up_xy, vp_xy, tp_xy;
  raypipe_hf_add #(E, S) u_det_xy (.a(r4.s.detx), .b(r4.s.dety), .sub(1'b0), .rm(RNE), .y(det_xy));
  raypipe_hf_add #(E, S) u_up_xy (.a(r4.s.upx), .b(r4.s.upy), .sub(1'b0), .rm(RNE), .y(up_xy));
  raypipe_hf_add #(E, S) u_vp_xy (.a(r4.s.vpx), .b(r4.s.vpy), .sub(1'b0), .rm(RNE), .y(vp_xy));
  raypipe_hf_add #(E, S) u_tp_xy (.a(r4.s.tpx), .b(r4.s.tpy), .sub(1'b0), .rm(RNE), .y(tp_xy));
  always @* begin
    n5 = r4;
    {n5.s.det_xy, n5.s.up_xy, n5.s.vp_xy, n5.s.tp_xy} = {det_xy, up_xy, vp_xy, tp_xy};
  end

  // ---- stage 6: + z
  wire [W-1:0] det, up, vp, tp;
  raypipe_hf_add #(E, S) u_det (.a(r5.s.det_xy), .b(r5.s.detz), .sub(1'b0), .rm(RNE), .y(det));
  raypipe_hf_add #(E, S) u_up (.a(r5.s.up_xy), .b(r5.s.upz), .sub(1'b0), .rm(RNE), .y(up));
  raypipe_hf_add #(E, S) u_vp (.a(r5.s.vp_xy), .b(r5.s.vpz), .sub(1'b0), .rm(RNE), .y(vp));
  raypipe_hf_add #(E, S) u_tp (.a(r5.s.tp_xy), .b(r5.s.tpz), .sub(1'b0), .rm(RNE), .y(tp));
  always @* begin
    n6 = r5;
    n6.s.det = det;
    {n6.s.up, n6.s.vp, n6.s.tp} = {up, vp, tp};
  end

  // ---- stage 7: u' + v', and the division-free validity test (the compares of det's sign)
  wire [W-1:0] uv;
  raypipe_hf_add #(E, S) u_uv (.a(r6.s.up), .b(r6.s.vp), .sub(1'b0), .rm(RNE), .y(uv));
  wire thr_lt_det, thr_lt_abs, pos, zu_le, zu_ge, zv_le, zv_ge, zt_le, zt_ge, uv_lt, uv_le, uv_ge;
  wire [W-1:0] abs_det = {1'b0, r6.s.det[W-2:0]};
  raypipe_hf_cmp #(E, S) c_thr (.a(THR), .b(r6.s.det), .lt(thr_lt_det), .le(), .ge());
  raypipe_hf_cmp #(E, S) c_thr_abs (.a(THR), .b(abs_det), .lt(thr_lt_abs), .le(), .ge());
  raypipe_hf_cmp #(E, S) c_pos (.a(ZERO), .b(r6.s.det), .lt(pos), .le(), .ge());
  raypipe_hf_cmp #(E, S) c_u (.a(ZERO), .b(r6.s.up), .lt(), .le(zu_le), .ge(zu_ge));
  raypipe_hf_cmp #(E, S) c_v (.a(ZERO), .b(r6.s.vp), .lt(), .le(zv_le), .ge(zv_ge));
  raypipe_hf_cmp #(E, S) c_t (.a(ZERO), .b(r6.s.tp), .lt(), .le(zt_le), .ge(zt_ge));
  raypipe_hf_cmp #(E, S) c_uv (.a(uv), .b(r6.s.det), .lt(uv_lt), .le(uv_le), .ge(uv_ge));
  // (combinational blocks are `always @*`: Icarus 11 re-runs an always_comb that writes a
  // struct member forever)
  wire det_ok = CULL_BACKFACE[0] ? thr_lt_det : thr_lt_abs;
  // det > 0 ? lo <= hi : hi <= lo
  wire u_ok = pos ? zu_le : zu_ge;
  wire v_ok = pos ? zv_le : zv_ge;
`ifdef RAYPIPE_HF_FAULT_UV_STRICT
  wire uv_ok = pos ? uv_lt : (uv_ge && !uv_le);
`else
  wire uv_ok = pos ? uv_le : uv_ge;
`endif
  wire t_ok = pos ? zt_le : zt_ge;
  always @* begin
    n7 = r6;
    n7.s.uv = uv;
    {n7.s.det_ok, n7.s.u_ok, n7.s.v_ok, n7.s.uv_ok, n7.s.t_ok} = {det_ok, u_ok, v_ok, uv_ok, t_ok};
    n7.s.valid = det_ok & u_ok & v_ok & uv_ok & t_ok;
  end

  // ---- stage 8: the division (N edges): 1 / det, or t', u', v' / det
  wire [W-1:0] q0, q1, q2;
  raypipe_hf_divbank #(E, S) d0 (.clk(clk), .rst_n(rst_n), .in_valid(v7), .a(RECIP ? ONE : r7.s.tp), .b(r7.s.det),
                                 .rm(RNE), .y(q0));
  if (!RECIP) begin : g_div
    raypipe_hf_divbank #(E, S) d1 (.clk(clk), .rst_n(rst_n), .in_valid(v7), .a(r7.s.up), .b(r7.s.det), .rm(RNE),
                                   .y(q1));
    raypipe_hf_divbank #(E, S) d2 (.clk(clk), .rst_n(rst_n), .in_valid(v7), .a(r7.s.vp), .b(r7.s.det), .rm(RNE),
                                   .y(q2));
  end else begin : g_recip
    assign q1 = '0;
    assign q2 = '0;
  end
  // the state of stage 7 waits N edges beside the dividers (they take the operands at the edge
  // that registers its first copy, and their results are registered N edges later)
  state_t dlast;
  logic dvlast;
  raypipe_hf_delay #($bits(state_t), ND) wait_div (.clk(clk), .rst_n(rst_n), .x_valid(v7), .x(r7), .v(dvlast), .d(dlast));
  always @* begin
    n8 = dlast;
`ifdef RAYPIPE_RECIP_MUL
    n8.s.inv_det = q0;
`else
    {n8.s.t, n8.s.u, n8.s.v} = {q0, q1, q2};
`endif
  end

  // ---- recip-mul stage 9: t, u, v = t', u', v' x (1 / det)
  wire [W-1:0] t9, u9, w9;
`ifdef RAYPIPE_RECIP_MUL
  raypipe_hf_mul #(E, S) u_t (.a(r8.s.tp), .b(r8.s.inv_det), .rm(RNE), .y(t9));
  raypipe_hf_mul #(E, S) u_u (.a(r8.s.up), .b(r8.s.inv_det), .rm(RNE), .y(u9));
  raypipe_hf_mul #(E, S) u_v (.a(r8.s.vp), .b(r8.s.inv_det), .rm(RNE), .y(w9));
`else
  assign {t9, u9, w9} = '0;
`endif
  always @* begin
    n9 = r8;
`ifdef RAYPIPE_RECIP_MUL
    {n9.s.t, n9.s.u, n9.s.v} = {t9, u9, w9};
`endif
  end

  // ---- the last stage: tmin <= t <= tmax
  state_t rl;
  assign rl = RECIP ? r9 : r8;
  wire tmin_le, tmax_ge;
  raypipe_hf_cmp #(E, S) c_tmin (.a(rl.i.tmin), .b(rl.s.t), .lt(), .le(tmin_le), .ge());
  raypipe_hf_cmp #(E, S) c_tmax (.a(rl.s.t), .b(rl.i.tmax), .lt(), .le(tmax_ge), .ge());
  always @* begin
    n10 = rl;
    n10.s.tmin_ok = tmin_le;
    n10.s.tmax_ok = tmax_ge;
    n10.s.hit = rl.s.valid & tmin_le & tmax_ge;
  end

  always_ff @(posedge clk) begin
    v0 <= rst_n & in_valid;
    r0 <= {in_row, {$bits(rti_stages_t) {1'b0}}};
    {v1, r1} <= {rst_n & v0, n1};
    {v2, r2} <= {rst_n & v1, n2};
    {v3, r3} <= {rst_n & v2, n3};
    {v4, r4} <= {rst_n & v3, n4};
    {v5, r5} <= {rst_n & v4, n5};
    {v6, r6} <= {rst_n & v5, n6};
    {v7, r7} <= {rst_n & v6, n7};
    {v8, r8} <= {rst_n & dvlast, n8};
    {v9, r9} <= {rst_n & v8, n9};
    {v10, r10} <= {rst_n & (RECIP ? v9 : v8), n10};
  end

  rti_expected_t o;
  assign o.valid = r10.s.valid;
  assign o.hit = r10.s.hit;
  assign o.t = r10.s.t;
  assign o.u = r10.s.u;
  assign o.v = r10.s.v;
  assign out_row = o;
  assign stg_row = r10.s;
  assign out_valid = v10;
endmodule
