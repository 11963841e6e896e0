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
#(
  parameter int E = raypipe_set_pkg::EXP,
  parameter int S = raypipe_set_pkg::MAN + 1,
  // the rows' widths (the set's; parameters because yosys 0.23 reads no package names in ranges)
  parameter int IN_W_ = raypipe_set_pkg::IN_W,
  parameter int OUT_W_ = raypipe_set_pkg::OUT_W,
  parameter int STG_W_ = raypipe_set_pkg::STG_W
) (
  input  logic              clk,
  input  logic              rst_n,
  input  logic              in_valid,
  input  logic [IN_W_-1:0]  in_row,
  output logic              out_valid,
  output logic [OUT_W_-1:0] out_row,
  output logic [STG_W_-1:0] stg_row
);
  // the row types: package-scoped for yosys 0.23 (which reads struct members only of a variable
  // declared pkg::type, and no wildcard import in a module), imported for Icarus 11 (which
  // aborts on a variable declared pkg::type)
`ifdef SYNTHESIS
`define RAYPIPE_HF_IN_T raypipe_rti_pkg::rti_inputs_t
`define RAYPIPE_HF_STG_T raypipe_rti_pkg::rti_stages_t
`else
  import raypipe_rti_pkg::*;
`define RAYPIPE_HF_IN_T rti_inputs_t
`define RAYPIPE_HF_STG_T rti_stages_t
`endif
  // the set's parameters (named through the package: yosys 0.23 reads no wildcard import)
  localparam logic [63:0] FTZ = raypipe_set_pkg::FTZ;
  localparam logic [63:0] NAN_PROPAGATE = raypipe_set_pkg::NAN_PROPAGATE;
  localparam logic [63:0] WIDTH = raypipe_set_pkg::WIDTH;
  localparam logic [63:0] DET_THR = raypipe_set_pkg::DET_THR;
  localparam logic [63:0] CULL_BACKFACE = raypipe_set_pkg::CULL_BACKFACE;
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

`ifndef SYNTHESIS  // elaboration checks (synthesis and formal tools skip them)
  initial begin
    if (FTZ != 0 || NAN_PROPAGATE != 0)
      $fatal(1, "raypipe_rti_hf: HardFloat (RISCV) computes the ieee+canonical options; this set has ftz=%0d propagate=%0d",
             FTZ, NAN_PROPAGATE);
    if (E + S != int'(WIDTH)) $fatal(1, "raypipe_rti_hf: the set's fields are not %0d bits", E + S);
  end
`endif

  // the state after a stage: its inputs part (riK) and its stage-signal part (rsK), laid out
  // like the set's in_row and stg_row (two variables of the package types, not one struct of two and
  // no typedef of them: yosys 0.23 reads struct members only of a variable declared pkg::type)
  // r[k]: the state after table stage k (r[0]: the input register); vk its valid bit
  `RAYPIPE_HF_IN_T ri0, ri1, ri2, ri3, ri4, ri5, ri6, ri7, ri8, ri9, ri10;
  `RAYPIPE_HF_STG_T rs0, rs1, rs2, rs3, rs4, rs5, rs6, rs7, rs8, rs9, rs10;
  logic v0, v1, v2, v3, v4, v5, v6, v7, v8, v9, v10;
  `RAYPIPE_HF_IN_T ni1, ni2, ni3, ni4, ni5, ni6, ni7, ni8, ni9, ni10;
  `RAYPIPE_HF_STG_T ns1, ns2, ns3, ns4, ns5, ns6, ns7, ns8, ns9, ns10;

  // ---- stage 1: e1 = v1 - v0, e2 = v2 - v0, s = o - v0
  wire [W-1:0] e1x, e1y, e1z, e2x, e2y, e2z, sx, sy, sz;
`ifdef RAYPIPE_HF_FAULT_E1X_SWAP
  raypipe_hf_add #(E, S) u_e1x (.a(ri0.v0x), .b(ri0.v1x), .sub(1'b1), .rm(RNE), .y(e1x));
`else
  raypipe_hf_add #(E, S) u_e1x (.a(ri0.v1x), .b(ri0.v0x), .sub(1'b1), .rm(RNE), .y(e1x));
`endif
  raypipe_hf_add #(E, S) u_e1y (.a(ri0.v1y), .b(ri0.v0y), .sub(1'b1), .rm(RNE), .y(e1y));
  raypipe_hf_add #(E, S) u_e1z (.a(ri0.v1z), .b(ri0.v0z), .sub(1'b1), .rm(RNE), .y(e1z));
  raypipe_hf_add #(E, S) u_e2x (.a(ri0.v2x), .b(ri0.v0x), .sub(1'b1), .rm(RNE), .y(e2x));
  raypipe_hf_add #(E, S) u_e2y (.a(ri0.v2y), .b(ri0.v0y), .sub(1'b1), .rm(RNE), .y(e2y));
  raypipe_hf_add #(E, S) u_e2z (.a(ri0.v2z), .b(ri0.v0z), .sub(1'b1), .rm(RNE), .y(e2z));
  raypipe_hf_add #(E, S) u_sx (.a(ri0.ox), .b(ri0.v0x), .sub(1'b1), .rm(RNE), .y(sx));
  raypipe_hf_add #(E, S) u_sy (.a(ri0.oy), .b(ri0.v0y), .sub(1'b1), .rm(RNE), .y(sy));
  raypipe_hf_add #(E, S) u_sz (.a(ri0.oz), .b(ri0.v0z), .sub(1'b1), .rm(RNE), .y(sz));
  always @* begin
    {ni1, ns1} = {ri0, rs0};
    {ns1.e1x, ns1.e1y, ns1.e1z, ns1.e2x, ns1.e2y, ns1.e2z} = {e1x, e1y, e1z, e2x, e2y, e2z};
    {ns1.sx, ns1.sy, ns1.sz} = {sx, sy, sz};
  end

  // ---- stage 2: the twelve products of p = d x e2 and q = s x e1
  wire [W-1:0] pxa, pxb, pya, pyb, pza, pzb, qxa, qxb, qya, qyb, qza, qzb;
  raypipe_hf_mul #(E, S) u_pxa (.a(ri1.dy), .b(rs1.e2z), .rm(RNE), .y(pxa));
  raypipe_hf_mul #(E, S) u_pxb (.a(ri1.dz), .b(rs1.e2y), .rm(RNE), .y(pxb));
  raypipe_hf_mul #(E, S) u_pya (.a(ri1.dz), .b(rs1.e2x), .rm(RNE), .y(pya));
  raypipe_hf_mul #(E, S) u_pyb (.a(ri1.dx), .b(rs1.e2z), .rm(RNE), .y(pyb));
  raypipe_hf_mul #(E, S) u_pza (.a(ri1.dx), .b(rs1.e2y), .rm(RNE), .y(pza));
  raypipe_hf_mul #(E, S) u_pzb (.a(ri1.dy), .b(rs1.e2x), .rm(RNE), .y(pzb));
  raypipe_hf_mul #(E, S) u_qxa (.a(rs1.sy), .b(rs1.e1z), .rm(RNE), .y(qxa));
  raypipe_hf_mul #(E, S) u_qxb (.a(rs1.sz), .b(rs1.e1y), .rm(RNE), .y(qxb));
  raypipe_hf_mul #(E, S) u_qya (.a(rs1.sz), .b(rs1.e1x), .rm(RNE), .y(qya));
  raypipe_hf_mul #(E, S) u_qyb (.a(rs1.sx), .b(rs1.e1z), .rm(RNE), .y(qyb));
  raypipe_hf_mul #(E, S) u_qza (.a(rs1.sx), .b(rs1.e1y), .rm(RNE), .y(qza));
  raypipe_hf_mul #(E, S) u_qzb (.a(rs1.sy), .b(rs1.e1x), .rm(RNE), .y(qzb));
  always @* begin
    {ni2, ns2} = {ri1, rs1};
    {ns2.pxa, ns2.pxb, ns2.pya, ns2.pyb, ns2.pza, ns2.pzb} = {pxa, pxb, pya, pyb, pza, pzb};
    {ns2.qxa, ns2.qxb, ns2.qya, ns2.qyb, ns2.qza, ns2.qzb} = {qxa, qxb, qya, qyb, qza, qzb};
  end

  // ---- stage 3: the cross products' subtracts
  wire [W-1:0] px, py, pz, qx, qy, qz;
  raypipe_hf_add #(E, S) u_px (.a(rs2.pxa), .b(rs2.pxb), .sub(1'b1), .rm(RNE), .y(px));
  raypipe_hf_add #(E, S) u_py (.a(rs2.pya), .b(rs2.pyb), .sub(1'b1), .rm(RNE), .y(py));
  raypipe_hf_add #(E, S) u_pz (.a(rs2.pza), .b(rs2.pzb), .sub(1'b1), .rm(RNE), .y(pz));
  raypipe_hf_add #(E, S) u_qx (.a(rs2.qxa), .b(rs2.qxb), .sub(1'b1), .rm(RNE), .y(qx));
  raypipe_hf_add #(E, S) u_qy (.a(rs2.qya), .b(rs2.qyb), .sub(1'b1), .rm(RNE), .y(qy));
  raypipe_hf_add #(E, S) u_qz (.a(rs2.qza), .b(rs2.qzb), .sub(1'b1), .rm(RNE), .y(qz));
  always @* begin
    {ni3, ns3} = {ri2, rs2};
    {ns3.px, ns3.py, ns3.pz, ns3.qx, ns3.qy, ns3.qz} = {px, py, pz, qx, qy, qz};
`ifdef RAYPIPE_HF_FAULT_QX_FTZ
    // a flush-to-zero wrapper on q.x: a subnormal becomes zero of its sign
    if (qx[W-2:S-1] == 0) ns3.qx = {qx[W-1], {(W - 1) {1'b0}}};
`endif
  end

  // ---- stage 4: the dot products' multiplies (det = e1.p, u' = s.p, v' = d.q, t' = e2.q)
  wire [W-1:0] detx, dety, detz, upx, upy, upz, vpx, vpy, vpz, tpx, tpy, tpz;
`ifdef RAYPIPE_HF_FAULT_DETX_RNA
  raypipe_hf_mul #(E, S) u_detx (.a(rs3.e1x), .b(rs3.px), .rm(3'b100), .y(detx));
`else
  raypipe_hf_mul #(E, S) u_detx (.a(rs3.e1x), .b(rs3.px), .rm(RNE), .y(detx));
`endif
  raypipe_hf_mul #(E, S) u_dety (.a(rs3.e1y), .b(rs3.py), .rm(RNE), .y(dety));
  raypipe_hf_mul #(E, S) u_detz (.a(rs3.e1z), .b(rs3.pz), .rm(RNE), .y(detz));
  raypipe_hf_mul #(E, S) u_upx (.a(rs3.sx), .b(rs3.px), .rm(RNE), .y(upx));
  raypipe_hf_mul #(E, S) u_upy (.a(rs3.sy), .b(rs3.py), .rm(RNE), .y(upy));
  raypipe_hf_mul #(E, S) u_upz (.a(rs3.sz), .b(rs3.pz), .rm(RNE), .y(upz));
  raypipe_hf_mul #(E, S) u_vpx (.a(ri3.dx), .b(rs3.qx), .rm(RNE), .y(vpx));
  raypipe_hf_mul #(E, S) u_vpy (.a(ri3.dy), .b(rs3.qy), .rm(RNE), .y(vpy));
  raypipe_hf_mul #(E, S) u_vpz (.a(ri3.dz), .b(rs3.qz), .rm(RNE), .y(vpz));
  raypipe_hf_mul #(E, S) u_tpx (.a(rs3.e2x), .b(rs3.qx), .rm(RNE), .y(tpx));
  raypipe_hf_mul #(E, S) u_tpy (.a(rs3.e2y), .b(rs3.qy), .rm(RNE), .y(tpy));
  raypipe_hf_mul #(E, S) u_tpz (.a(rs3.e2z), .b(rs3.qz), .rm(RNE), .y(tpz));
  always @* begin
    {ni4, ns4} = {ri3, rs3};
    {ns4.detx, ns4.dety, ns4.detz, ns4.upx, ns4.upy, ns4.upz} = {detx, dety, detz, upx, upy, upz};
    {ns4.vpx, ns4.vpy, ns4.vpz, ns4.tpx, ns4.tpy, ns4.tpz} = {vpx, vpy, vpz, tpx, tpy, tpz};
  end

  // ---- stage 5: x + y of each dot product
  wire [W-1:0] det_xy, up_xy, vp_xy, tp_xy;
  raypipe_hf_add #(E, S) u_det_xy (.a(rs4.detx), .b(rs4.dety), .sub(1'b0), .rm(RNE), .y(det_xy));
  raypipe_hf_add #(E, S) u_up_xy (.a(rs4.upx), .b(rs4.upy), .sub(1'b0), .rm(RNE), .y(up_xy));
  raypipe_hf_add #(E, S) u_vp_xy (.a(rs4.vpx), .b(rs4.vpy), .sub(1'b0), .rm(RNE), .y(vp_xy));
  raypipe_hf_add #(E, S) u_tp_xy (.a(rs4.tpx), .b(rs4.tpy), .sub(1'b0), .rm(RNE), .y(tp_xy));
  always @* begin
    {ni5, ns5} = {ri4, rs4};
    {ns5.det_xy, ns5.up_xy, ns5.vp_xy, ns5.tp_xy} = {det_xy, up_xy, vp_xy, tp_xy};
  end

  // ---- stage 6: + z
  wire [W-1:0] det, up, vp, tp;
  raypipe_hf_add #(E, S) u_det (.a(rs5.det_xy), .b(rs5.detz), .sub(1'b0), .rm(RNE), .y(det));
  raypipe_hf_add #(E, S) u_up (.a(rs5.up_xy), .b(rs5.upz), .sub(1'b0), .rm(RNE), .y(up));
  raypipe_hf_add #(E, S) u_vp (.a(rs5.vp_xy), .b(rs5.vpz), .sub(1'b0), .rm(RNE), .y(vp));
  raypipe_hf_add #(E, S) u_tp (.a(rs5.tp_xy), .b(rs5.tpz), .sub(1'b0), .rm(RNE), .y(tp));
  always @* begin
    {ni6, ns6} = {ri5, rs5};
    ns6.det = det;
    {ns6.up, ns6.vp, ns6.tp} = {up, vp, tp};
  end

  // ---- stage 7: u' + v', and the division-free validity test (the compares of det's sign)
  wire [W-1:0] uv;
  raypipe_hf_add #(E, S) u_uv (.a(rs6.up), .b(rs6.vp), .sub(1'b0), .rm(RNE), .y(uv));
  wire thr_lt_det, thr_lt_abs, pos, zu_le, zu_ge, zv_le, zv_ge, zt_le, zt_ge, uv_lt, uv_le, uv_ge;
  wire [W-1:0] abs_det = {1'b0, rs6.det[W-2:0]};
  raypipe_hf_cmp #(E, S) c_thr (.a(THR), .b(rs6.det), .lt(thr_lt_det), .le(), .ge());
  raypipe_hf_cmp #(E, S) c_thr_abs (.a(THR), .b(abs_det), .lt(thr_lt_abs), .le(), .ge());
  raypipe_hf_cmp #(E, S) c_pos (.a(ZERO), .b(rs6.det), .lt(pos), .le(), .ge());
  raypipe_hf_cmp #(E, S) c_u (.a(ZERO), .b(rs6.up), .lt(), .le(zu_le), .ge(zu_ge));
  raypipe_hf_cmp #(E, S) c_v (.a(ZERO), .b(rs6.vp), .lt(), .le(zv_le), .ge(zv_ge));
  raypipe_hf_cmp #(E, S) c_t (.a(ZERO), .b(rs6.tp), .lt(), .le(zt_le), .ge(zt_ge));
  raypipe_hf_cmp #(E, S) c_uv (.a(uv), .b(rs6.det), .lt(uv_lt), .le(uv_le), .ge(uv_ge));
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
    {ni7, ns7} = {ri6, rs6};
    ns7.uv = uv;
    {ns7.det_ok, ns7.u_ok, ns7.v_ok, ns7.uv_ok, ns7.t_ok} = {det_ok, u_ok, v_ok, uv_ok, t_ok};
    ns7.valid = det_ok & u_ok & v_ok & uv_ok & t_ok;
  end

  // ---- stage 8: the division (N edges): 1 / det, or t', u', v' / det
  wire [W-1:0] q0, q1, q2;
  raypipe_hf_divbank #(E, S) d0 (.clk(clk), .rst_n(rst_n), .in_valid(v7), .a(RECIP ? ONE : rs7.tp), .b(rs7.det),
                                 .rm(RNE), .y(q0));
  if (!RECIP) begin : g_div
    raypipe_hf_divbank #(E, S) d1 (.clk(clk), .rst_n(rst_n), .in_valid(v7), .a(rs7.up), .b(rs7.det), .rm(RNE),
                                   .y(q1));
    raypipe_hf_divbank #(E, S) d2 (.clk(clk), .rst_n(rst_n), .in_valid(v7), .a(rs7.vp), .b(rs7.det), .rm(RNE),
                                   .y(q2));
  end else begin : g_recip
    assign q1 = '0;
    assign q2 = '0;
  end
  // the state of stage 7 waits N edges beside the dividers (they take the operands at the edge
  // that registers its first copy, and their results are registered N edges later)
  `RAYPIPE_HF_IN_T dlasti;
  `RAYPIPE_HF_STG_T dlasts;
  logic [IN_W_+STG_W_-1:0] dlast;
  logic dvlast;
  raypipe_hf_delay #(IN_W_ + STG_W_, ND) wait_div (.clk(clk), .rst_n(rst_n), .x_valid(v7), .x({ri7, rs7}), .v(dvlast), .d(dlast));
  assign {dlasti, dlasts} = dlast;
  always @* begin
    {ni8, ns8} = {dlasti, dlasts};
`ifdef RAYPIPE_RECIP_MUL
    ns8.inv_det = q0;
`else
    {ns8.t, ns8.u, ns8.v} = {q0, q1, q2};
`endif
  end

  // ---- recip-mul stage 9: t, u, v = t', u', v' x (1 / det)
  wire [W-1:0] t9, u9, w9;
`ifdef RAYPIPE_RECIP_MUL
  raypipe_hf_mul #(E, S) u_t (.a(rs8.tp), .b(rs8.inv_det), .rm(RNE), .y(t9));
  raypipe_hf_mul #(E, S) u_u (.a(rs8.up), .b(rs8.inv_det), .rm(RNE), .y(u9));
  raypipe_hf_mul #(E, S) u_v (.a(rs8.vp), .b(rs8.inv_det), .rm(RNE), .y(w9));
`else
  assign {t9, u9, w9} = '0;
`endif
  always @* begin
    {ni9, ns9} = {ri8, rs8};
`ifdef RAYPIPE_RECIP_MUL
    {ns9.t, ns9.u, ns9.v} = {t9, u9, w9};
`endif
  end

  // ---- the last stage: tmin <= t <= tmax
  `RAYPIPE_HF_IN_T rli;
  `RAYPIPE_HF_STG_T rls;
  assign {rli, rls} = RECIP ? {ri9, rs9} : {ri8, rs8};
  wire tmin_le, tmax_ge;
  raypipe_hf_cmp #(E, S) c_tmin (.a(rli.tmin), .b(rls.t), .lt(), .le(tmin_le), .ge());
  raypipe_hf_cmp #(E, S) c_tmax (.a(rls.t), .b(rli.tmax), .lt(), .le(tmax_ge), .ge());
  always @* begin
    {ni10, ns10} = {rli, rls};
    ns10.tmin_ok = tmin_le;
    ns10.tmax_ok = tmax_ge;
    ns10.hit = rls.valid & tmin_le & tmax_ge;
  end

  always_ff @(posedge clk) begin
    v0 <= rst_n & in_valid;
    {ri0, rs0} <= {in_row, {STG_W_ {1'b0}}};
    {v1, ri1, rs1} <= {rst_n & v0, ni1, ns1};
    {v2, ri2, rs2} <= {rst_n & v1, ni2, ns2};
    {v3, ri3, rs3} <= {rst_n & v2, ni3, ns3};
    {v4, ri4, rs4} <= {rst_n & v3, ni4, ns4};
    {v5, ri5, rs5} <= {rst_n & v4, ni5, ns5};
    {v6, ri6, rs6} <= {rst_n & v5, ni6, ns6};
    {v7, ri7, rs7} <= {rst_n & v6, ni7, ns7};
    {v8, ri8, rs8} <= {rst_n & dvlast, ni8, ns8};
    {v9, ri9, rs9} <= {rst_n & v8, ni9, ns9};
    {v10, ri10, rs10} <= {rst_n & (RECIP ? v9 : v8), ni10, ns10};
  end

`ifdef SYNTHESIS
  raypipe_rti_pkg::rti_expected_t o;
`else
  rti_expected_t o;
`endif
  assign o.valid = rs10.valid;
  assign o.hit = rs10.hit;
  assign o.t = rs10.t;
  assign o.u = rs10.u;
  assign o.v = rs10.v;
  assign out_row = o;
  assign stg_row = rs10;
  assign out_valid = v10;
`undef RAYPIPE_HF_IN_T
`undef RAYPIPE_HF_STG_T
endmodule
