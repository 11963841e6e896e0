// raypipe's third-party datapath: the operations of the stage tables as Berkeley HardFloat units
// (hdl/third_party/hardfloat, Release 1, BSD 3-clause; RISCV specialisation).
//
// Every stage signal of the datapaths is registered as an IEEE encoding of expWidth exponent and
// sigWidth - 1 fraction bits (what the probes show). Each operation below recodes its operands
// (fNToRecFN), computes in HardFloat's recoded format (addRecFN with subOp, mulRecFN,
// compareRecFN, divSqrtRecFN_small) and converts the result back (recFNToFN). A design keeping
// recoded values between stages computes the same bits: recFNToFN(fNToRecFN(x)) = x for every
// non-NaN x, and under the RISCV specialisation every NaN result is the default NaN whatever the
// operands' payloads.
//
// Rounding: each unit takes its roundingMode port (the datapaths tie it to 000, nearest-even;
// a fault of hdl/hardfloat/README.md changes it on one unit). Tininess is detected after
// rounding (control = 1): that only sets the underflow flag, which no output uses.
`include "HardFloat_consts.vi"

// a + b (sub = 0) or a - b (sub = 1), rounded once.
module raypipe_hf_add #(parameter int E = 8, parameter int S = 24) (
  input  logic [E+S-1:0] a,
  input  logic [E+S-1:0] b,
  input  logic           sub,
  input  logic [2:0]     rm,
  output logic [E+S-1:0] y
);
  wire [E+S:0] ra, rb, ry;
  wire [4:0] flags;
  fNToRecFN #(E, S) in_a (.in(a), .out(ra));
  fNToRecFN #(E, S) in_b (.in(b), .out(rb));
  addRecFN #(E, S) op (.control(`flControl_tininessAfterRounding), .subOp(sub), .a(ra), .b(rb),
                       .roundingMode(rm), .out(ry), .exceptionFlags(flags));
  recFNToFN #(E, S) out (.in(ry), .out(y));
endmodule

// a x b, rounded once.
module raypipe_hf_mul #(parameter int E = 8, parameter int S = 24) (
  input  logic [E+S-1:0] a,
  input  logic [E+S-1:0] b,
  input  logic [2:0]     rm,
  output logic [E+S-1:0] y
);
  wire [E+S:0] ra, rb, ry;
  wire [4:0] flags;
  fNToRecFN #(E, S) in_a (.in(a), .out(ra));
  fNToRecFN #(E, S) in_b (.in(b), .out(rb));
  mulRecFN #(E, S) op (.control(`flControl_tininessAfterRounding), .a(ra), .b(rb), .roundingMode(rm),
                       .out(ry), .exceptionFlags(flags));
  recFNToFN #(E, S) out (.in(ry), .out(y));
endmodule

// The quiet IEEE compare of a and b: lt = a < b, le = a <= b, ge = a >= b (all false when either
// is NaN; -0 equals +0).
module raypipe_hf_cmp #(parameter int E = 8, parameter int S = 24) (
  input  logic [E+S-1:0] a,
  input  logic [E+S-1:0] b,
  output logic           lt,
  output logic           le,
  output logic           ge
);
  wire [E+S:0] ra, rb;
  wire lt_, eq_, gt_, unordered;
  wire [4:0] flags;
  fNToRecFN #(E, S) in_a (.in(a), .out(ra));
  fNToRecFN #(E, S) in_b (.in(b), .out(rb));
  compareRecFN #(E, S) op (.a(ra), .b(rb), .signaling(1'b0), .lt(lt_), .eq(eq_), .gt(gt_),
                           .unordered(unordered), .exceptionFlags(flags));
  assign lt = lt_;
  assign le = lt_ | eq_;
  assign ge = gt_ | eq_;
endmodule

// a / b at one test per clock and a fixed latency of N = S + 2 clock edges, from N sequential
// divSqrtRecFN_small units taken in turn (unit i takes the operands presented in the cycles
// where the turn counter is i, i.e. every N-th cycle, whether in_valid is set or not).
// divSqrtRecFN_small accepts an operation when its cycle counter is <= 1 and, for finite nonzero
// operands, raises outValid S + 1 edges after the edge that took them (S edges when its
// remainder lets it skip a cycle); for a NaN, infinite or zero operand, on the next edge. Its
// result registers hold until the next operation enters. So the result of the operation taken
// at edge e is on unit i's output in the cycle before edge e + N, when the turn is i again: y
// presents the result of the unit whose turn it is, and the caller registers y at the edge
// e + N (its other signals travel through N plain registers meanwhile, the first filled at
// edge e). A unit that is not
// ready when its turn comes with in_valid (which the timing above excludes) stops the
// simulation.
module raypipe_hf_divbank #(parameter int E = 8, parameter int S = 24) (
  input  logic           clk,
  input  logic           rst_n,
  input  logic           in_valid,
  input  logic [E+S-1:0] a,
  input  logic [E+S-1:0] b,
  input  logic [2:0]     rm,
  output logic [E+S-1:0] y
);
  localparam int N = S + 2;
  localparam int R = E + S + 1;  // recoded width
  logic [$clog2(N+1)-1:0] turn;
  always_ff @(posedge clk) begin
    if (!rst_n) turn <= '0;
    else turn <= (turn == N - 1) ? '0 : turn + 1'b1;
  end
  // divSqrtRecFN_small's data registers (exponent, quotient bits) have no reset and are loaded
  // only by a finite nonzero operation; a unit whose first operation has a NaN, infinite or zero
  // operand rounds them (its flags then select the result) and gives X in simulation. So while
  // rst_n is low every unit takes 1 / 1 (entering needs no reset), which defines them.
  localparam logic [E+S-1:0] ONE = (E + S)'(((1 << (E - 1)) - 1)) << (S - 1);
  wire [R-1:0] ra, rb;
  fNToRecFN #(E, S) in_a (.in(rst_n ? a : ONE), .out(ra));
  fNToRecFN #(E, S) in_b (.in(rst_n ? b : ONE), .out(rb));
  wire [N*R-1:0] outs;
  wire [N-1:0] ready;
  genvar i;
  for (i = 0; i < N; i = i + 1) begin : g_unit
    wire out_valid, sqrt_out;
    wire [4:0] flags;
    divSqrtRecFN_small #(E, S) unit (
      .nReset(rst_n), .clock(clk), .control(`flControl_tininessAfterRounding),
      .inReady(ready[i]), .inValid(!rst_n || (in_valid && turn == i)), .sqrtOp(1'b0), .a(ra), .b(rb), .roundingMode(rm),
      .outValid(out_valid), .sqrtOpOut(sqrt_out), .out(outs[i*R +: R]),
      .exceptionFlags(flags));
  end
  recFNToFN #(E, S) out (.in(outs[turn*R +: R]), .out(y));
`ifndef SYNTHESIS  // a simulation check (the timing above excludes it)
  always @(posedge clk) begin
    if (rst_n && in_valid && !ready[turn])
      $fatal(1, "raypipe_hf_divbank: unit %0d not ready when its turn came", turn);
  end
`endif
endmodule

// A row and its valid bit delayed by N >= 2 clock edges (the state of a datapath waiting beside
// raypipe_hf_divbank): d is x as registered N edges ago; v is rst_n & x_valid likewise.
module raypipe_hf_delay #(parameter int W = 1, parameter int N = 2) (
  input  logic         clk,
  input  logic         rst_n,
  input  logic         x_valid,
  input  logic [W-1:0] x,
  output logic         v,
  output logic [W-1:0] d
);
  // dl[1..N-1] an array, the last word a plain variable (Icarus 11 misses updates of
  // generate-written array words); one always_ff per register (Verilator 5.006 has no delayed
  // assignment to arrays in loops)
  logic [W-1:0] dl [1:N-1];
  logic dv [1:N-1];
  always_ff @(posedge clk) begin
    dl[1] <= x;
    dv[1] <= rst_n & x_valid;
  end
  for (genvar k = 2; k < N; k++) begin : g_wait
    always_ff @(posedge clk) begin
      dl[k] <= dl[k-1];
      dv[k] <= rst_n & dv[k-1];
    end
  end
  always_ff @(posedge clk) begin
    d <= dl[N-1];
    v <= rst_n & dv[N-1];
  end
endmodule
