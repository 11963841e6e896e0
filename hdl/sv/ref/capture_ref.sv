// Reference DUT of the `capture` unit (raypipe HDL kit): the min-capture unit as a 4-stage
// pipeline, stage k + 1 taking slot k of one ray's leaf of RTI results. Each vector starts
// from the reset state (no hit held: hit 0, t, u, v +0, id 0). Slot k is taken when hit_k is 1
// and no hit is held or t_k < held t (t_k <= held t when TIE_LAST: the tie rule `last`), IEEE
// ordered compares (NaN false, -0 == +0) after the format's operand read. Latency 4; every
// stage's take bit and state are carried to the end and presented on stg_row.
// Bank faults (docs/faults.md) this DUT can carry, one define each (the kit's negative checks):
//   RAYPIPE_FAULT_CAPTURE_TAKE_TIE    capture.take.tie: the other tie rule
//   RAYPIPE_FAULT_CAPTURE_HIT_STUCK1  capture.hit.stuck1: a miss is taken too
//   RAYPIPE_FAULT_CAPTURE_HELD_STUCK1 capture.held.stuck1: the first hit compared with t = +0
module raypipe_capture_ref
  import raypipe_fp::*;
  import raypipe_set_pkg::*;
  import raypipe_capture_pkg::*;
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
  localparam int W = WIDTH[7:0];

  // one slot of an input row, as it is packed there (and the held state's layout)
  typedef struct packed {
    logic hit;
    logic [W-1:0] t;
    logic [W-1:0] u;
    logic [W-1:0] v;
    logic [31:0] id;
  } result_t;

  // a slot's take bit and the state after it, as packed in capture_stages.hex
  typedef struct packed {
    logic take;
    result_t c;
  } slot_state_t;

  localparam int S = $bits(slot_state_t);

  // the pipeline state: the input row and, per slot k, its take bit and the state after it
  // (slot 0 in the most significant bits: the layout of capture_stages.hex)
  typedef struct packed {
    capture_inputs_t i;
    logic [L*S-1:0] s;
  } state_t;

  // the result of slot k of an input row (slots MSB first after the class byte)
  function automatic result_t slot(capture_inputs_t x, int k);
    logic [$bits(capture_inputs_t)-9:0] all;
    all = x[$bits(capture_inputs_t)-9:0];
    return all[(L - 1 - k) * $bits(result_t) +: $bits(result_t)];
  endfunction

  // the decision: take r over the held state h
  function automatic logic take_of(result_t r, result_t h);
    logic hit, held, cmp;
    hit = r.hit;
    held = h.hit;
`ifdef RAYPIPE_FAULT_CAPTURE_HIT_STUCK1
    hit = 1'b1;
`endif
`ifdef RAYPIPE_FAULT_CAPTURE_HELD_STUCK1
    held = 1'b1;
`endif
`ifdef RAYPIPE_FAULT_CAPTURE_TAKE_TIE
    cmp = TIE_LAST[0] ? flt(F, r.t, h.t) : fle(F, r.t, h.t);
`else
    cmp = TIE_LAST[0] ? fle(F, r.t, h.t) : flt(F, r.t, h.t);
`endif
    return hit && (!held || cmp);
  endfunction

  // stage k + 1: slot k taken (or not) over the state after slot k - 1 (the reset state for k = 0)
  function automatic state_t stage(int k, state_t x);
    state_t y = x;
    logic [L*S-1:0] all;
    slot_state_t h, n;
    result_t r;
    all = x.s;
    h = (k == 0) ? '0 : all[(L - k) * S +: S];
    r = slot(x.i, k);
    n.take = take_of(r, h.c);
    n.c = n.take ? r : h.c;
    if (n.take) n.c.hit = 1'b1;
    all[(L - 1 - k) * S +: S] = n;
    y.s = all;
    return y;
  endfunction

  // st[k] / v[k]: the state and valid bit after stage register k (0 = the input register)
  state_t st [0:L-1];
  logic v [0:L-1];
  state_t last;
  always_ff @(posedge clk) begin
    v[0] <= rst_n & in_valid;
    st[0] <= {in_row, {L * S{1'b0}}};
  end
  for (genvar k = 1; k < L; k++) begin : g_stage
    always_ff @(posedge clk) begin
      v[k] <= rst_n & v[k-1];
      st[k] <= stage(k - 1, st[k-1]);
    end
  end
  always_ff @(posedge clk) begin
    out_valid <= rst_n & v[L-1];
    last <= stage(L - 1, st[L-1]);
  end

  slot_state_t fin;
  assign fin = last.s[S-1:0];
  assign out_row = fin.c;
  assign stg_row = last.s;
endmodule
