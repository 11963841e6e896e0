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
  import raypipe_set_pkg::*;
  import raypipe_slab_pkg::*;
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

  initial begin
    if (FTZ != 0 || NAN_PROPAGATE != 0)
      $fatal(1, "raypipe_slab_hf: HardFloat (RISCV) computes the ieee+canonical options; this set has ftz=%0d propagate=%0d",
             FTZ, NAN_PROPAGATE);
    if (E + S != int'(WIDTH)) $fatal(1, "raypipe_slab_hf: the set's fields are not %0d bits", E + S);
  end

  // ---- glue on IEEE encodings
  function automatic logic is_nan(logic [W-1:0] a);
    return &a[W-2:S-1] && |a[S-2:0];
  endfunction
  function automatic logic is_inf(logic [W-1:0] a);
    return &a[W-2:S-1] && !(|a[S-2:0]);
  endfunction
  function automatic logic is_zero(logic [W-1:0] a);
    return !(|a[W-2:0]);
  endfunction
  function automatic logic is_sub(logic [W-1:0] a);
    return !(|a[W-2:S-1]) && |a[S-2:0];
  endfunction
  function automatic logic finite(logic [W-1:0] a);
    return !(&a[W-2:S-1]);
  endfunction
  // the input read: a NaN reads as the canonical NaN
  function automatic logic [W-1:0] read(logic [W-1:0] a);
    return is_nan(a) ? QNAN : a;
  endfunction
  // IEEE nextUp (NaN and +inf unchanged; +-0 -> least subnormal)
  function automatic logic [W-1:0] next_up(logic [W-1:0] a);
    if (is_nan(a) || a == {1'b0, {E{1'b1}}, {(S - 1) {1'b0}}}) return a;
    if (is_zero(a)) return 1;
    return a[W-1] ? a - 1'b1 : a + 1'b1;
  endfunction
  function automatic logic [W-1:0] next_down(logic [W-1:0] a);
    if (is_nan(a)) return a;
    return next_up(a ^ {1'b1, {(W - 1) {1'b0}}}) ^ {1'b1, {(W - 1) {1'b0}}};
  endfunction
  function automatic logic [W-1:0] widen(logic [W-1:0] t, logic up);
    for (int j = 0; j < int'(SLAB_WIDEN_ULPS); j++) t = up ? next_up(t) : next_down(t);
    return t;
  endfunction

  typedef struct packed {
    slab_inputs_t i;
    slab_stages_t s;
  } state_t;

  state_t r0, r1, r2, r3, r4, r5, r6, r7;
  logic v0, v1, v2, v3, v4, v5, v6, v7;
  state_t n0, n1, n2, n3, n4, n5, n6, n7;

  // ---- stage 0 (N edges): read, preparation, reciprocals
  logic [W-1:0] dx, dy, dz;
  assign {dx, dy, dz} = {read(r0.i.dx), read(r0.i.dy), read(r0.i.dz)};
  wire [W-1:0] ndelta;
  raypipe_hf_add #(E, S) u_ndelta (.a(ZERO), .b(DELTA), .sub(1'b1), .rm(RNE), .y(ndelta));
  wire smallx, smally, smallz;
  raypipe_hf_cmp #(E, S) c_px (.a({1'b0, dx[W-2:0]}), .b(DELTA), .lt(smallx), .le(), .ge());
  raypipe_hf_cmp #(E, S) c_py (.a({1'b0, dy[W-2:0]}), .b(DELTA), .lt(smally), .le(), .ge());
  raypipe_hf_cmp #(E, S) c_pz (.a({1'b0, dz[W-2:0]}), .b(DELTA), .lt(smallz), .le(), .ge());
  always @* begin
    n0 = r0;
    {n0.s.dx, n0.s.dy, n0.s.dz} = {dx, dy, dz};
    {n0.i.ox, n0.i.oy, n0.i.oz} = {read(r0.i.ox), read(r0.i.oy), read(r0.i.oz)};
    {n0.i.tmin, n0.i.tmax} = {read(r0.i.tmin), read(r0.i.tmax)};
    n0.s.pdx = SLAB_EMBREE[0] && smallx ? (dx[W-1] ? ndelta : DELTA) : dx;
    n0.s.pdy = SLAB_EMBREE[0] && smally ? (dy[W-1] ? ndelta : DELTA) : dy;
    n0.s.pdz = SLAB_EMBREE[0] && smallz ? (dz[W-1] ? ndelta : DELTA) : dz;
  end
  wire [W-1:0] rx, ry, rz;
  raypipe_hf_divbank #(E, S) d_x (.clk(clk), .rst_n(rst_n), .in_valid(v0), .a(ONE), .b(n0.s.pdx), .rm(RNE), .y(rx));
  raypipe_hf_divbank #(E, S) d_y (.clk(clk), .rst_n(rst_n), .in_valid(v0), .a(ONE), .b(n0.s.pdy), .rm(RNE), .y(ry));
  raypipe_hf_divbank #(E, S) d_z (.clk(clk), .rst_n(rst_n), .in_valid(v0), .a(ONE), .b(n0.s.pdz), .rm(RNE), .y(rz));
  // the state waits N edges beside the dividers (they take the operands at the edge
  // that registers its first copy, and their results are registered N edges later)
  state_t dlast;
  logic dvlast;
  raypipe_hf_delay #($bits(state_t), ND) wait_div (.clk(clk), .rst_n(rst_n), .x_valid(v0), .x(n0), .v(dvlast), .d(dlast));
  // the guard: a finite nonzero d whose reciprocal is not a normal number
  function automatic logic [W-1:0] guard_recip(logic [W-1:0] d, logic [W-1:0] r);
    if (GUARD && finite(d) && !is_zero(d) && (is_inf(r) || is_zero(r) || is_sub(r))) return QNAN;
    return r;
  endfunction
  always @* begin
    n1 = dlast;
    n1.s.inv_dx = guard_recip(dlast.s.pdx, rx);
    n1.s.inv_dy = guard_recip(dlast.s.pdy, ry);
    n1.s.inv_dz = guard_recip(dlast.s.pdz, rz);
  end

  // ---- stage 1: b - o; the guard: finite operands whose difference overflowed
  wire [W-1:0] lox, hix, loy, hiy, loz, hiz;
`ifdef RAYPIPE_HF_FAULT_LOX_SWAP
  raypipe_hf_add #(E, S) u_lox (.a(r1.i.ox), .b(r1.i.minx), .sub(1'b1), .rm(RNE), .y(lox));
`else
  raypipe_hf_add #(E, S) u_lox (.a(r1.i.minx), .b(r1.i.ox), .sub(1'b1), .rm(RNE), .y(lox));
`endif
  raypipe_hf_add #(E, S) u_hix (.a(r1.i.maxx), .b(r1.i.ox), .sub(1'b1), .rm(RNE), .y(hix));
  raypipe_hf_add #(E, S) u_loy (.a(r1.i.miny), .b(r1.i.oy), .sub(1'b1), .rm(RNE), .y(loy));
  raypipe_hf_add #(E, S) u_hiy (.a(r1.i.maxy), .b(r1.i.oy), .sub(1'b1), .rm(RNE), .y(hiy));
  raypipe_hf_add #(E, S) u_loz (.a(r1.i.minz), .b(r1.i.oz), .sub(1'b1), .rm(RNE), .y(loz));
  raypipe_hf_add #(E, S) u_hiz (.a(r1.i.maxz), .b(r1.i.oz), .sub(1'b1), .rm(RNE), .y(hiz));
  function automatic logic [W-1:0] guard_sub(logic [W-1:0] a, logic [W-1:0] b, logic [W-1:0] r);
    if (GUARD_SUB && finite(a) && finite(b) && is_inf(r)) return QNAN;
    return r;
  endfunction
  always @* begin
    n2 = r1;
    n2.s.lox = guard_sub(r1.i.minx, r1.i.ox, lox);
    n2.s.hix = guard_sub(r1.i.maxx, r1.i.ox, hix);
    n2.s.loy = guard_sub(r1.i.miny, r1.i.oy, loy);
    n2.s.hiy = guard_sub(r1.i.maxy, r1.i.oy, hiy);
    n2.s.loz = guard_sub(r1.i.minz, r1.i.oz, loz);
    n2.s.hiz = guard_sub(r1.i.maxz, r1.i.oz, hiz);
  end

  // ---- stage 2: (b - o) x (1 / d)
  wire [W-1:0] tlox, thix, tloy, thiy, tloz, thiz;
  raypipe_hf_mul #(E, S) u_tlox (.a(r2.s.lox), .b(r2.s.inv_dx), .rm(RNE), .y(tlox));
  raypipe_hf_mul #(E, S) u_thix (.a(r2.s.hix), .b(r2.s.inv_dx), .rm(RNE), .y(thix));
  raypipe_hf_mul #(E, S) u_tloy (.a(r2.s.loy), .b(r2.s.inv_dy), .rm(RNE), .y(tloy));
  raypipe_hf_mul #(E, S) u_thiy (.a(r2.s.hiy), .b(r2.s.inv_dy), .rm(RNE), .y(thiy));
  raypipe_hf_mul #(E, S) u_tloz (.a(r2.s.loz), .b(r2.s.inv_dz), .rm(RNE), .y(tloz));
`ifdef RAYPIPE_HF_FAULT_THIZ_RUP
  raypipe_hf_mul #(E, S) u_thiz (.a(r2.s.hiz), .b(r2.s.inv_dz), .rm(3'b011), .y(thiz));
`else
  raypipe_hf_mul #(E, S) u_thiz (.a(r2.s.hiz), .b(r2.s.inv_dz), .rm(RNE), .y(thiz));
`endif
  always @* begin
    n3 = r2;
    {n3.s.tlox, n3.s.thix, n3.s.tloy, n3.s.thiy, n3.s.tloz, n3.s.thiz} = {tlox, thix, tloy, thiy, tloz, thiz};
  end

  // ---- stage 3: near / far by the sign bit of 1 / d
  // (combinational blocks are `always @*`: Icarus 11 re-runs an always_comb that writes a
  // struct member forever)
  wire negx = r3.s.inv_dx[W-1], negy = r3.s.inv_dy[W-1], negz = r3.s.inv_dz[W-1];
  always @* begin
    n4 = r3;
    {n4.s.negx, n4.s.negy, n4.s.negz} = {negx, negy, negz};
    n4.s.nearx = negx ? r3.s.thix : r3.s.tlox;
    n4.s.farx = negx ? r3.s.tlox : r3.s.thix;
    n4.s.neary = negy ? r3.s.thiy : r3.s.tloy;
    n4.s.fary = negy ? r3.s.tloy : r3.s.thiy;
    n4.s.nearz = negz ? r3.s.thiz : r3.s.tloz;
    n4.s.farz = negz ? r3.s.tloz : r3.s.thiz;
  end

  // ---- stage 4: the compare-select chains (near: the largest, far: the smallest)
  // plain: take x when acc < x (near) / x < acc (far); take-on-false: keep acc when x <= acc
  // (near) / acc <= x (far), so a NaN x is taken
  wire [W-1:0] tn_x, tn_xy, tn_xyz, tf_x, tf_xy, tf_xyz;
  wire n_lt_x, n_le_x, n_lt_y, n_le_y, n_lt_z, n_le_z;  // acc < x, x <= acc
  wire f_lt_x, f_le_x, f_lt_y, f_le_y, f_lt_z, f_le_z;  // x < acc, acc <= x
  raypipe_hf_cmp #(E, S) c_nx (.a(r4.i.tmin), .b(r4.s.nearx), .lt(n_lt_x), .le(), .ge(n_le_x));
  assign tn_x = SLAB_TAKE_ON_FALSE[0] ? (n_le_x ? r4.i.tmin : r4.s.nearx) : (n_lt_x ? r4.s.nearx : r4.i.tmin);
  raypipe_hf_cmp #(E, S) c_ny (.a(tn_x), .b(r4.s.neary), .lt(n_lt_y), .le(), .ge(n_le_y));
  assign tn_xy = SLAB_TAKE_ON_FALSE[0] ? (n_le_y ? tn_x : r4.s.neary) : (n_lt_y ? r4.s.neary : tn_x);
  raypipe_hf_cmp #(E, S) c_nz (.a(tn_xy), .b(r4.s.nearz), .lt(n_lt_z), .le(), .ge(n_le_z));
  assign tn_xyz = SLAB_TAKE_ON_FALSE[0] ? (n_le_z ? tn_xy : r4.s.nearz) : (n_lt_z ? r4.s.nearz : tn_xy);
  raypipe_hf_cmp #(E, S) c_fx (.a(r4.s.farx), .b(r4.i.tmax), .lt(f_lt_x), .le(), .ge(f_le_x));
  assign tf_x = SLAB_TAKE_ON_FALSE[0] ? (f_le_x ? r4.i.tmax : r4.s.farx) : (f_lt_x ? r4.s.farx : r4.i.tmax);
  raypipe_hf_cmp #(E, S) c_fy (.a(r4.s.fary), .b(tf_x), .lt(f_lt_y), .le(), .ge(f_le_y));
  assign tf_xy = SLAB_TAKE_ON_FALSE[0] ? (f_le_y ? tf_x : r4.s.fary) : (f_lt_y ? r4.s.fary : tf_x);
  raypipe_hf_cmp #(E, S) c_fz (.a(r4.s.farz), .b(tf_xy), .lt(f_lt_z), .le(), .ge(f_le_z));
  assign tf_xyz = SLAB_TAKE_ON_FALSE[0] ? (f_le_z ? tf_xy : r4.s.farz) : (f_lt_z ? r4.s.farz : tf_xy);
  always @* begin
    n5 = r4;
    {n5.s.tn_x, n5.s.tn_xy, n5.s.tn_xyz, n5.s.tf_x, n5.s.tf_xy, n5.s.tf_xyz} = {tn_x, tn_xy, tn_xyz, tf_x, tf_xy, tf_xyz};
  end

  // ---- stage 5: widening
  always @* begin
    n6 = r5;
    n6.s.t_near = widen(r5.s.tn_xyz, 1'b0);
    n6.s.t_far = widen(r5.s.tf_xyz, 1'b1);
  end

  // ---- stage 6: hit = t_near <= t_far
  wire hit_lt, hit_le;
  raypipe_hf_cmp #(E, S) c_hit (.a(r6.s.t_near), .b(r6.s.t_far), .lt(hit_lt), .le(hit_le), .ge());
  always @* begin
    n7 = r6;
`ifdef RAYPIPE_HF_FAULT_HIT_STRICT
    n7.s.hit = hit_lt;
`else
    n7.s.hit = hit_le;
`endif
  end

  always_ff @(posedge clk) begin
    v0 <= rst_n & in_valid;
    r0 <= {in_row, {$bits(slab_stages_t) {1'b0}}};
    {v1, r1} <= {rst_n & dvlast, n1};
    {v2, r2} <= {rst_n & v1, n2};
    {v3, r3} <= {rst_n & v2, n3};
    {v4, r4} <= {rst_n & v3, n4};
    {v5, r5} <= {rst_n & v4, n5};
    {v6, r6} <= {rst_n & v5, n6};
    {v7, r7} <= {rst_n & v6, n7};
  end

  slab_expected_t o;
  assign o.hit = r7.s.hit;
  assign o.t_near = r7.s.t_near;
  assign o.t_far = r7.s.t_far;
  assign out_row = o;
  assign stg_row = r7.s;
  assign out_valid = v7;
endmodule
