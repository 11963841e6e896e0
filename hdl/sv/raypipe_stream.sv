// raypipe HDL kit: a valid/ready (AXI4-Stream style) unit made from a fixed-latency core with the
// kit's ports (raypipe_tb.sv: in_valid/in_row in, out_valid/out_row/stg_row out, one result
// exactly LATENCY edges after each input, no backpressure).
//
// The core's results go into a FIFO of DEPTH rows (out_row and stg_row); the unit takes an input
// (in_ready = 1) only while the rows in the core plus the rows in the FIFO are fewer than DEPTH,
// so every result the core produces has a place, whatever the core's latency and however long
// out_ready stays low. Results leave in input order; a result is offered (out_valid) while the
// FIFO is not empty and leaves at an edge with out_ready = 1. With DEPTH >= the core's latency
// + 1 and out_ready always 1, the unit takes one input per clock.
//
// The core is the module named by the CORE macro (hdl/run --handshake sets it: the unit's
// reference DUT, or your --dut). Define RAYPIPE_FAULT_STREAM_DROP for a protocol bug: the FIFO
// drops its head at an edge where out_valid is 1 and out_ready is 0 (a result lost under a
// stall; the testbench must fail).
`ifndef CORE
`define CORE raypipe_rti_ref
`endif
module raypipe_stream_of
  import raypipe_set_pkg::*;
#(
  parameter int DEPTH = 64
) (
  input  logic             clk,
  input  logic             rst_n,
  input  logic             in_valid,
  output logic             in_ready,
  input  logic [IN_W-1:0]  in_row,
  output logic             out_valid,
  input  logic             out_ready,
  output logic [OUT_W-1:0] out_row,
  output logic [STG_W-1:0] stg_row
);
  localparam int AW = $clog2(DEPTH + 1);
  logic core_valid;
  logic [OUT_W-1:0] core_out;
  logic [STG_W-1:0] core_stg;
  wire take = in_valid && in_ready;
  `CORE core (.clk(clk), .rst_n(rst_n), .in_valid(take), .in_row(in_row), .out_valid(core_valid),
              .out_row(core_out), .stg_row(core_stg));

  logic [OUT_W+STG_W-1:0] mem [0:DEPTH-1];
  logic [AW-1:0] rp, wp, count, inflight;
  wire pop = out_valid && (out_ready
`ifdef RAYPIPE_FAULT_STREAM_DROP
                           || 1'b1
`endif
                          );
  assign out_valid = count != 0;
  assign in_ready = rst_n && (inflight + count < DEPTH);
  always @(posedge clk) begin
    if (!rst_n) begin
      rp <= '0;
      wp <= '0;
      count <= '0;
      inflight <= '0;
    end else begin
      if (core_valid) begin
        mem[wp] <= {core_out, core_stg};
        wp <= (wp == DEPTH - 1) ? '0 : wp + 1'b1;
      end
      if (pop) rp <= (rp == DEPTH - 1) ? '0 : rp + 1'b1;
      count <= count + AW'(core_valid) - AW'(pop);
      inflight <= inflight + AW'(take) - AW'(core_valid);
    end
  end
  always @* {out_row, stg_row} = mem[rp];
endmodule
