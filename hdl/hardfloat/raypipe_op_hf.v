// The `op` unit's combinational operations as Berkeley HardFloat units, in plain Verilog-2001
// (what yosys reads): add, sub and mul rounded once to nearest-even, and the ordered compares
// lt and le. Ports are named as raypipe's op model signals (raypipe smt --unit op), so
// `raypipe equiv --unit op` proves each output equal to the model's signal of the same name for
// every pair of encodings. Each operation recodes its operands (fNToRecFN), computes in
// HardFloat's recoded format and converts back (recFNToFN); under the RISCV specialisation
// every NaN result is the default NaN, raypipe's canonical NaN. The division is HardFloat's
// iterative divSqrtRecFN_small (sequential), so it is not here.
//
// Faults (one define each), each a counterexample for raypipe equiv:
//   RAYPIPE_HF_FAULT_MUL_RUP    the multiplier's roundingMode tied to 011 (toward +inf)
//   RAYPIPE_HF_FAULT_SUB_SWAP   sub computes b - a
//   RAYPIPE_HF_FAULT_LE_STRICT  le computed as lt
`include "HardFloat_consts.vi"

module raypipe_op_hf #(parameter E = 5, parameter S = 11) (
  input  [E+S-1:0] a,
  input  [E+S-1:0] b,
  output [E+S-1:0] add,
  output [E+S-1:0] sub,
  output [E+S-1:0] mul,
  output           lt,
  output           le
);
  wire [E+S:0] ra, rb, radd, rsub, rmul;
  wire [4:0] f_add, f_sub, f_mul, f_cmp;
  wire c_lt, c_eq, c_gt, c_un;
`ifdef RAYPIPE_HF_FAULT_MUL_RUP
  wire [2:0] rm_mul = `round_max;
`else
  wire [2:0] rm_mul = `round_near_even;
`endif
  fNToRecFN #(E, S) in_a (.in(a), .out(ra));
  fNToRecFN #(E, S) in_b (.in(b), .out(rb));
  addRecFN #(E, S) u_add (.control(`flControl_tininessAfterRounding), .subOp(1'b0), .a(ra), .b(rb),
                          .roundingMode(`round_near_even), .out(radd), .exceptionFlags(f_add));
`ifdef RAYPIPE_HF_FAULT_SUB_SWAP
  addRecFN #(E, S) u_sub (.control(`flControl_tininessAfterRounding), .subOp(1'b1), .a(rb), .b(ra),
                          .roundingMode(`round_near_even), .out(rsub), .exceptionFlags(f_sub));
`else
  addRecFN #(E, S) u_sub (.control(`flControl_tininessAfterRounding), .subOp(1'b1), .a(ra), .b(rb),
                          .roundingMode(`round_near_even), .out(rsub), .exceptionFlags(f_sub));
`endif
  mulRecFN #(E, S) u_mul (.control(`flControl_tininessAfterRounding), .a(ra), .b(rb),
                          .roundingMode(rm_mul), .out(rmul), .exceptionFlags(f_mul));
  compareRecFN #(E, S) u_cmp (.a(ra), .b(rb), .signaling(1'b0), .lt(c_lt), .eq(c_eq), .gt(c_gt),
                              .unordered(c_un), .exceptionFlags(f_cmp));
  recFNToFN #(E, S) out_add (.in(radd), .out(add));
  recFNToFN #(E, S) out_sub (.in(rsub), .out(sub));
  recFNToFN #(E, S) out_mul (.in(rmul), .out(mul));
  assign lt = c_lt;
`ifdef RAYPIPE_HF_FAULT_LE_STRICT
  assign le = c_lt;
`else
  assign le = c_lt | c_eq;
`endif
endmodule
