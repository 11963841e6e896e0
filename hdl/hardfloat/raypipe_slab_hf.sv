// The `slab` ray-box unit assembled from Berkeley HardFloat units (raypipe_hf_ops.sv): raypipe's
// slab stage table (0: direction read, preparation and the three reciprocals; 1: six subtracts;
// 2: six multiplies; 3: near/far by the sign of 1/d; 4: the compare-select chains from
// tmin/tmax in axis order x, y, z; 5: widening by SLAB_WIDEN_ULPS grid steps; 6: hit =
// t_near <= t_far). One register per table stage, except stage 0, which takes N + 1 clock edges,
// N = S + 2 (raypipe_hf_divbank: N dividers per axis in turn take the operands at one edge and
// their result is registered N edges later; one test per clock): latency = the set's LATENCY
// + S + 2. Same ports as the kit's reference DUTs; every stage signal on stg_row.
//
// HardFloat does the arithmetic and the compares; the variant's rules are glue logic on the
// IEEE encodings around it, written here:
//   * input read: a NaN input reads as the canonical NaN (HardFloat would carry its payload
//     through fNToRecFN / recFNToFN into the stage signals dx, dy, dz);
//   * Embree's preparation (SLAB_EMBREE): |d| < SLAB_DELTA becomes +-SLAB_DELTA by d's sign bit;
//   * the conservative guard (SLAB_GUARD): a finite nonzero d whose reciprocal is +-inf, +-0 or
//     subnormal, and a stage-1 difference of finite operands that overflowed to +-inf, give the
//     canonical NaN;
//   * compare-select (plain: take x when acc < x; SLAB_TAKE_ON_FALSE: keep acc when x <= acc);
//   * widening: SLAB_WIDEN_ULPS steps of IEEE nextDown (t_near) / nextUp (t_far).
// The format comes from the set (raypipe_set_pkg): E = EXP, S = MAN + 1; a set with `ftz` or
// `propagate` is refused at elaboration (HardFloat's RISCV specialisation computes neither).
// Faults (one define each; hdl/hardfloat/README.md):
//   RAYPIPE_HF_FAULT_LOX_SWAP     lo.x = o.x - min.x (operand swap)
//   RAYPIPE_HF_FAULT_HIT_STRICT   t_near <= t_far tested as < (strict compare)
//   RAYPIPE_HF_FAULT_NO_GUARD_SUB the conservative guard's overflowed-subtract check left out
//   RAYPIPE_HF_FAULT_THIZ_RUP     the thi.z multiplier's roundingMode port tied to 011 (toward +inf)
// Each is the bank fault of the same name in raypipe's fault model (slab.lox.swap,
// slab.hit.strict, slab.guard_sub.stuck0, slab.thiz.rup): hdl/hardfloat/selftest checks that the
// RTL fails first at the vector where `raypipe faults` first detects the modelled fault.
module raypipe_slab_hf
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
`define RAYPIPE_HF_IN_T raypipe_slab_pkg::slab_inputs_t
`define RAYPIPE_HF_STG_T raypipe_slab_pkg::slab_stages_t
`else
  import raypipe_slab_pkg::*;
`define RAYPIPE_HF_IN_T slab_inputs_t
`define RAYPIPE_HF_STG_T slab_stages_t
`endif
  // the set's parameters (named through the package: yosys 0.23 reads no wildcard import)
  localparam logic [63:0] FTZ = raypipe_set_pkg::FTZ;
  localparam logic [63:0] NAN_PROPAGATE = raypipe_set_pkg::NAN_PROPAGATE;
  localparam logic [63:0] WIDTH = raypipe_set_pkg::WIDTH;
  localparam logic [63:0] SLAB_DELTA = raypipe_set_pkg::SLAB_DELTA;
  localparam logic [63:0] SLAB_GUARD = raypipe_set_pkg::SLAB_GUARD;
  localparam logic [63:0] SLAB_EMBREE = raypipe_set_pkg::SLAB_EMBREE;
  localparam logic [63:0] SLAB_TAKE_ON_FALSE = raypipe_set_pkg::SLAB_TAKE_ON_FALSE;
  localparam logic [63:0] SLAB_WIDEN_ULPS = raypipe_set_pkg::SLAB_WIDEN_ULPS;
  localparam int W = E + S;
  localparam int ND = S + 2;  // edges of stage 0
  localparam logic [2:0] RNE = 3'b000;
  localparam logic [W-1:0] ZERO = '0;
  localparam logic [W-1:0] ONE = W'(((1 << (E - 1)) - 1)) << (S - 1);
  localparam logic [W-1:0] QNAN = ({W{1'b1}} >> 1) & ~(({W{1'b1}} >> (E + 2)));  // exp all ones, top fraction bit
  localparam logic [W-1:0] DELTA = SLAB_DELTA[W-1:0];
  localparam logic GUARD = SLAB_GUARD[0];
`ifdef RAYPIPE_HF_FAULT_NO_GUARD_SUB
  localparam logic GUARD_SUB = 1'b0;
`else
  localparam logic GUARD_SUB = GUARD;
`endif

`ifndef SYNTHESIS  // elaboration checks (synthesis and formal tools skip them)
  initial begin
    if (FTZ != 0 || NAN_PROPAGATE != 0)
      $fatal(1, "raypipe_slab_hf: HardFloat (RISCV) computes the ieee+canonical options; this set has ftz=%0d propagate=%0d",
             FTZ, NAN_PROPAGATE);
    if (E + S != int'(WIDTH)) $fatal(1, "raypipe_slab_hf: the set's fields are not %0d bits", E + S);
  end
`endif

  // ---- glue on IEEE encodings
  // (results assigned to the function's name, not returned: yosys 0.23 reads no `return`)
  function automatic logic is_nan(logic [W-1:0] a);
    is_nan = &a[W-2:S-1] && |a[S-2:0];
  endfunction
  function automatic logic is_inf(logic [W-1:0] a);
    is_inf = &a[W-2:S-1] && !(|a[S-2:0]);
  endfunction
  function automatic logic is_zero(logic [W-1:0] a);
    is_zero = !(|a[W-2:0]);
  endfunction
  function automatic logic is_sub(logic [W-1:0] a);
    is_sub = !(|a[W-2:S-1]) && |a[S-2:0];
  endfunction
  function automatic logic finite(logic [W-1:0] a);
    finite = !(&a[W-2:S-1]);
  endfunction
  // the input read: a NaN reads as the canonical NaN
  function automatic logic [W-1:0] read(logic [W-1:0] a);
    read = is_nan(a) ? QNAN : a;
  endfunction
  // IEEE nextUp (NaN and +inf unchanged; +-0 -> least subnormal)
  function automatic logic [W-1:0] next_up(logic [W-1:0] a);
    if (is_nan(a) || a == {1'b0, {E{1'b1}}, {(S - 1) {1'b0}}}) next_up = a;
    else if (is_zero(a)) next_up = 1;
    else next_up = a[W-1] ? a - 1'b1 : a + 1'b1;
  endfunction
  function automatic logic [W-1:0] next_down(logic [W-1:0] a);
    if (is_nan(a)) next_down = a;
    else next_down = next_up(a ^ {1'b1, {(W - 1) {1'b0}}}) ^ {1'b1, {(W - 1) {1'b0}}};
  endfunction
  function automatic logic [W-1:0] widen(logic [W-1:0] t, logic up);
    for (int j = 0; j < SLAB_WIDEN_ULPS; j++) t = up ? next_up(t) : next_down(t);
    widen = t;
  endfunction

  // the state after a stage: its inputs part (riK) and its stage-signal part (rsK), laid out
  // like the set's in_row and stg_row (two variables of the package types, not one struct of two and
  // no typedef of them: yosys 0.23 reads struct members only of a variable declared pkg::type)
  `RAYPIPE_HF_IN_T ri0, ri1, ri2, ri3, ri4, ri5, ri6, ri7;
  `RAYPIPE_HF_STG_T rs0, rs1, rs2, rs3, rs4, rs5, rs6, rs7;
  logic v0, v1, v2, v3, v4, v5, v6, v7;
  `RAYPIPE_HF_IN_T ni0, ni1, ni2, ni3, ni4, ni5, ni6, ni7;
  `RAYPIPE_HF_STG_T ns0, ns1, ns2, ns3, ns4, ns5, ns6, ns7;

  // ---- stage 0 (N edges): read, preparation, reciprocals
  logic [W-1:0] dx, dy, dz;
  assign {dx, dy, dz} = {read(ri0.dx), read(ri0.dy), read(ri0.dz)};
  wire [W-1:0] ndelta;
  raypipe_hf_add #(E, S) u_ndelta (.a(ZERO), .b(DELTA), .sub(1'b1), .rm(RNE), .y(ndelta));
  wire smallx, smally, smallz;
  raypipe_hf_cmp #(E, S) c_px (.a({1'b0, dx[W-2:0]}), .b(DELTA), .lt(smallx), .le(), .ge());
  raypipe_hf_cmp #(E, S) c_py (.a({1'b0, dy[W-2:0]}), .b(DELTA), .lt(smally), .le(), .ge());
  raypipe_hf_cmp #(E, S) c_pz (.a({1'b0, dz[W-2:0]}), .b(DELTA), .lt(smallz), .le(), .ge());
  always @* begin
    {ni0, ns0} = {ri0, rs0};
    {ns0.dx, ns0.dy, ns0.dz} = {dx, dy, dz};
    {ni0.ox, ni0.oy, ni0.oz} = {read(ri0.ox), read(ri0.oy), read(ri0.oz)};
    {ni0.tmin, ni0.tmax} = {read(ri0.tmin), read(ri0.tmax)};
    ns0.pdx = SLAB_EMBREE[0] && smallx ? (dx[W-1] ? ndelta : DELTA) : dx;
    ns0.pdy = SLAB_EMBREE[0] && smally ? (dy[W-1] ? ndelta : DELTA) : dy;
    ns0.pdz = SLAB_EMBREE[0] && smallz ? (dz[W-1] ? ndelta : DELTA) : dz;
  end
  wire [W-1:0] rx, ry, rz;
  raypipe_hf_divbank #(E, S) d_x (.clk(clk), .rst_n(rst_n), .in_valid(v0), .a(ONE), .b(ns0.pdx), .rm(RNE), .y(rx));
  raypipe_hf_divbank #(E, S) d_y (.clk(clk), .rst_n(rst_n), .in_valid(v0), .a(ONE), .b(ns0.pdy), .rm(RNE), .y(ry));
  raypipe_hf_divbank #(E, S) d_z (.clk(clk), .rst_n(rst_n), .in_valid(v0), .a(ONE), .b(ns0.pdz), .rm(RNE), .y(rz));
  // the state waits N edges beside the dividers (they take the operands at the edge
  // that registers its first copy, and their results are registered N edges later)
  `RAYPIPE_HF_IN_T dlasti;
  `RAYPIPE_HF_STG_T dlasts;
  logic [IN_W_+STG_W_-1:0] dlast;
  logic dvlast;
  raypipe_hf_delay #(IN_W_ + STG_W_, ND) wait_div (.clk(clk), .rst_n(rst_n), .x_valid(v0), .x({ni0, ns0}), .v(dvlast), .d(dlast));
  assign {dlasti, dlasts} = dlast;
  // the guard: a finite nonzero d whose reciprocal is not a normal number
  function automatic logic [W-1:0] guard_recip(logic [W-1:0] d, logic [W-1:0] r);
    guard_recip = GUARD && finite(d) && !is_zero(d) && (is_inf(r) || is_zero(r) || is_sub(r)) ? QNAN : r;
  endfunction
  always @* begin
    {ni1, ns1} = {dlasti, dlasts};
    ns1.inv_dx = guard_recip(dlasts.pdx, rx);
    ns1.inv_dy = guard_recip(dlasts.pdy, ry);
    ns1.inv_dz = guard_recip(dlasts.pdz, rz);
  end

  // ---- stage 1: b - o; the guard: finite operands whose difference overflowed
  wire [W-1:0] lox, hix, loy, hiy, loz, hiz;
`ifdef RAYPIPE_HF_FAULT_LOX_SWAP
  raypipe_hf_add #(E, S) u_lox (.a(ri1.ox), .b(ri1.minx), .sub(1'b1), .rm(RNE), .y(lox));
`else
  raypipe_hf_add #(E, S) u_lox (.a(ri1.minx), .b(ri1.ox), .sub(1'b1), .rm(RNE), .y(lox));
`endif
  raypipe_hf_add #(E, S) u_hix (.a(ri1.maxx), .b(ri1.ox), .sub(1'b1), .rm(RNE), .y(hix));
  raypipe_hf_add #(E, S) u_loy (.a(ri1.miny), .b(ri1.oy), .sub(1'b1), .rm(RNE), .y(loy));
  raypipe_hf_add #(E, S) u_hiy (.a(ri1.maxy), .b(ri1.oy), .sub(1'b1), .rm(RNE), .y(hiy));
  raypipe_hf_add #(E, S) u_loz (.a(ri1.minz), .b(ri1.oz), .sub(1'b1), .rm(RNE), .y(loz));
  raypipe_hf_add #(E, S) u_hiz (.a(ri1.maxz), .b(ri1.oz), .sub(1'b1), .rm(RNE), .y(hiz));
  function automatic logic [W-1:0] guard_sub(logic [W-1:0] a, logic [W-1:0] b, logic [W-1:0] r);
    guard_sub = GUARD_SUB && finite(a) && finite(b) && is_inf(r) ? QNAN : r;
  endfunction
  always @* begin
    {ni2, ns2} = {ri1, rs1};
    ns2.lox = guard_sub(ri1.minx, ri1.ox, lox);
    ns2.hix = guard_sub(ri1.maxx, ri1.ox, hix);
    ns2.loy = guard_sub(ri1.miny, ri1.oy, loy);
    ns2.hiy = guard_sub(ri1.maxy, ri1.oy, hiy);
    ns2.loz = guard_sub(ri1.minz, ri1.oz, loz);
    ns2.hiz = guard_sub(ri1.maxz, ri1.oz, hiz);
  end

  // ---- stage 2: (b - o) x (1 / d)
  wire [W-1:0] tlox, thix, tloy, thiy, tloz, thiz;
  raypipe_hf_mul #(E, S) u_tlox (.a(rs2.lox), .b(rs2.inv_dx), .rm(RNE), .y(tlox));
  raypipe_hf_mul #(E, S) u_thix (.a(rs2.hix), .b(rs2.inv_dx), .rm(RNE), .y(thix));
  raypipe_hf_mul #(E, S) u_tloy (.a(rs2.loy), .b(rs2.inv_dy), .rm(RNE), .y(tloy));
  raypipe_hf_mul #(E, S) u_thiy (.a(rs2.hiy), .b(rs2.inv_dy), .rm(RNE), .y(thiy));
  raypipe_hf_mul #(E, S) u_tloz (.a(rs2.loz), .b(rs2.inv_dz), .rm(RNE), .y(tloz));
`ifdef RAYPIPE_HF_FAULT_THIZ_RUP
  raypipe_hf_mul #(E, S) u_thiz (.a(rs2.hiz), .b(rs2.inv_dz), .rm(3'b011), .y(thiz));
`else
  raypipe_hf_mul #(E, S) u_thiz (.a(rs2.hiz), .b(rs2.inv_dz), .rm(RNE), .y(thiz));
`endif
  always @* begin
    {ni3, ns3} = {ri2, rs2};
    {ns3.tlox, ns3.thix, ns3.tloy, ns3.thiy, ns3.tloz, ns3.thiz} = {tlox, thix, tloy, thiy, tloz, thiz};
  end

  // ---- stage 3: near / far by the sign bit of 1 / d
  // (combinational blocks are `always @*`: Icarus 11 re-runs an always_comb that writes a
  // struct member forever)
  wire negx = rs3.inv_dx[W-1], negy = rs3.inv_dy[W-1], negz = rs3.inv_dz[W-1];
  always @* begin
    {ni4, ns4} = {ri3, rs3};
    {ns4.negx, ns4.negy, ns4.negz} = {negx, negy, negz};
    ns4.nearx = negx ? rs3.thix : rs3.tlox;
    ns4.farx = negx ? rs3.tlox : rs3.thix;
    ns4.neary = negy ? rs3.thiy : rs3.tloy;
    ns4.fary = negy ? rs3.tloy : rs3.thiy;
    ns4.nearz = negz ? rs3.thiz : rs3.tloz;
    ns4.farz = negz ? rs3.tloz : rs3.thiz;
  end

  // ---- stage 4: the compare-select chains (near: the largest, far: the smallest)
  // plain: take x when acc < x (near) / x < acc (far); take-on-false: keep acc when x <= acc
  // (near) / acc <= x (far), so a NaN x is taken
  wire [W-1:0] tn_x, tn_xy, tn_xyz, tf_x, tf_xy, tf_xyz;
  wire n_lt_x, n_le_x, n_lt_y, n_le_y, n_lt_z, n_le_z;  // acc < x, x <= acc
  wire f_lt_x, f_le_x, f_lt_y, f_le_y, f_lt_z, f_le_z;  // x < acc, acc <= x
  raypipe_hf_cmp #(E, S) c_nx (.a(ri4.tmin), .b(rs4.nearx), .lt(n_lt_x), .le(), .ge(n_le_x));
  assign tn_x = SLAB_TAKE_ON_FALSE[0] ? (n_le_x ? ri4.tmin : rs4.nearx) : (n_lt_x ? rs4.nearx : ri4.tmin);
  raypipe_hf_cmp #(E, S) c_ny (.a(tn_x), .b(rs4.neary), .lt(n_lt_y), .le(), .ge(n_le_y));
  assign tn_xy = SLAB_TAKE_ON_FALSE[0] ? (n_le_y ? tn_x : rs4.neary) : (n_lt_y ? rs4.neary : tn_x);
  raypipe_hf_cmp #(E, S) c_nz (.a(tn_xy), .b(rs4.nearz), .lt(n_lt_z), .le(), .ge(n_le_z));
  assign tn_xyz = SLAB_TAKE_ON_FALSE[0] ? (n_le_z ? tn_xy : rs4.nearz) : (n_lt_z ? rs4.nearz : tn_xy);
  raypipe_hf_cmp #(E, S) c_fx (.a(rs4.farx), .b(ri4.tmax), .lt(f_lt_x), .le(), .ge(f_le_x));
  assign tf_x = SLAB_TAKE_ON_FALSE[0] ? (f_le_x ? ri4.tmax : rs4.farx) : (f_lt_x ? rs4.farx : ri4.tmax);
  raypipe_hf_cmp #(E, S) c_fy (.a(rs4.fary), .b(tf_x), .lt(f_lt_y), .le(), .ge(f_le_y));
  assign tf_xy = SLAB_TAKE_ON_FALSE[0] ? (f_le_y ? tf_x : rs4.fary) : (f_lt_y ? rs4.fary : tf_x);
  raypipe_hf_cmp #(E, S) c_fz (.a(rs4.farz), .b(tf_xy), .lt(f_lt_z), .le(), .ge(f_le_z));
  assign tf_xyz = SLAB_TAKE_ON_FALSE[0] ? (f_le_z ? tf_xy : rs4.farz) : (f_lt_z ? rs4.farz : tf_xy);
  always @* begin
    {ni5, ns5} = {ri4, rs4};
    {ns5.tn_x, ns5.tn_xy, ns5.tn_xyz, ns5.tf_x, ns5.tf_xy, ns5.tf_xyz} = {tn_x, tn_xy, tn_xyz, tf_x, tf_xy, tf_xyz};
  end

  // ---- stage 5: widening
  always @* begin
    {ni6, ns6} = {ri5, rs5};
    ns6.t_near = widen(rs5.tn_xyz, 1'b0);
    ns6.t_far = widen(rs5.tf_xyz, 1'b1);
  end

  // ---- stage 6: hit = t_near <= t_far
  wire hit_lt, hit_le;
  raypipe_hf_cmp #(E, S) c_hit (.a(rs6.t_near), .b(rs6.t_far), .lt(hit_lt), .le(hit_le), .ge());
  always @* begin
    {ni7, ns7} = {ri6, rs6};
`ifdef RAYPIPE_HF_FAULT_HIT_STRICT
    ns7.hit = hit_lt;
`else
    ns7.hit = hit_le;
`endif
  end

  always_ff @(posedge clk) begin
    v0 <= rst_n & in_valid;
    {ri0, rs0} <= {in_row, {STG_W_ {1'b0}}};
    {v1, ri1, rs1} <= {rst_n & dvlast, ni1, ns1};
    {v2, ri2, rs2} <= {rst_n & v1, ni2, ns2};
    {v3, ri3, rs3} <= {rst_n & v2, ni3, ns3};
    {v4, ri4, rs4} <= {rst_n & v3, ni4, ns4};
    {v5, ri5, rs5} <= {rst_n & v4, ni5, ns5};
    {v6, ri6, rs6} <= {rst_n & v5, ni6, ns6};
    {v7, ri7, rs7} <= {rst_n & v6, ni7, ns7};
  end

`ifdef SYNTHESIS
  raypipe_slab_pkg::slab_expected_t o;
`else
  slab_expected_t o;
`endif
  assign o.hit = rs7.hit;
  assign o.t_near = rs7.t_near;
  assign o.t_far = rs7.t_far;
  assign out_row = o;
  assign stg_row = rs7;
`ifdef RAYPIPE_HF_FAULT_VALID_EARLY
  assign out_valid = v6;  // a fault: out_valid one edge before its row
`else
  assign out_valid = v7;
`endif
`undef RAYPIPE_HF_IN_T
`undef RAYPIPE_HF_STG_T
endmodule
