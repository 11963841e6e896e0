// Reference DUT of the `op` unit: one operation per vector, latency 1 (raypipe HDL kit).
// in_row = {class, opcode, a, b}; out_row = {result, cmp}. Opcodes: 0 add, 1 sub, 2 mul,
// 3 div (the datapath's division: a / b, or a x (1 / b) in recip-mul formats), 4 lt, 5 le.
module raypipe_op_ref
  import raypipe_fp::*;
  import raypipe_set_pkg::*;
  import raypipe_op_pkg::*;
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

  function automatic op_expected_t eval(op_inputs_t x);
    op_expected_t r;
    r = '0;
    case (x.opcode)
      4'd0: r.result = fadd(F, x.a, x.b);
      4'd1: r.result = fsub(F, x.a, x.b);
      4'd2: r.result = fmul(F, x.a, x.b);
      4'd3: r.result = fdivide(F, RECIP_MUL[0], x.a, x.b);
      4'd4: r.cmp = flt(F, x.a, x.b);
      default: r.cmp = fle(F, x.a, x.b);
    endcase
    return r;
  endfunction

  // the kit's valid-timing negative checks: RAYPIPE_EXTRA_PULSE raises out_valid for one more
  // cycle (the first idle one after the 10th result); RAYPIPE_DROP_PULSE leaves out the 10th result's pulse
  int results;
  logic extra_done;
  logic v0;
  op_inputs_t s0;
  always_ff @(posedge clk) begin
    if (!rst_n) begin
      v0 <= 1'b0;
      out_valid <= 1'b0;
      results <= 0;
      extra_done <= 1'b0;
    end else begin
      v0 <= in_valid;
      s0 <= in_row;
      out_valid <= v0;
      out_row <= eval(s0);
      if (v0) results <= results + 1;
`ifdef RAYPIPE_DROP_PULSE
      if (v0 && results == 9) out_valid <= 1'b0;
`endif
`ifdef RAYPIPE_EXTRA_PULSE
      if (!v0 && results >= 10 && !extra_done) begin
        out_valid <= 1'b1;
        extra_done <= 1'b1;
      end
`endif
    end
  end
  assign stg_row = '0;
endmodule
