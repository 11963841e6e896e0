// raypipe HDL kit: valid/ready (AXI4-Stream style) streams around fixed-latency cores.
//
// raypipe_stream_fifo: the result FIFO and input credits that turn any core with a fixed
//   latency and no backpressure into a valid/ready unit. The core's results go into a FIFO of
//   DEPTH rows; the unit takes an input (in_ready = 1) only while the rows in the core plus the
//   rows in the FIFO are fewer than DEPTH, so every result the core produces has a place,
//   whatever the core's latency and however long out_ready stays low. Results leave in input
//   order; a result is offered (out_valid) while the FIFO is not empty and leaves at an edge
//   with out_ready = 1. With DEPTH >= the core's latency + 1 and out_ready always 1, the unit
//   takes one input per clock. An id (IDW bits) given with each input comes out with its result.
//   With RAYPIPE_STREAM_SWAP the results leave through raypipe_stream_swap (out of order).
//   Define RAYPIPE_FAULT_STREAM_DROP for a protocol bug: the FIFO drops its head at an edge
//   where out_valid is 1 and out_ready is 0 (a result lost under a stall; a testbench must fail).
//
// raypipe_stream_swap: a test of a testbench's out-of-order matching: it passes results on with
//   each two consecutive ones swapped (a result waits up to 8 cycles for its partner, then goes
//   alone), ids and all.
//
// raypipe_stream_of: the kit's ports (raypipe_tb.sv) with valid/ready around the core named by
//   the CORE macro (hdl/run --handshake sets it: the unit's reference DUT, or your --dut); with
//   RAYPIPE_ID_W defined it has the in_id / out_id ports of raypipe_stream_tb.sv, and with
//   RAYPIPE_STREAM_SWAP its FIFO delivers results out of order.
module raypipe_stream_fifo #(
  parameter int W = 1,
  parameter int IDW = 1,
  parameter int DEPTH = 64
) (
  input  logic           clk,
  input  logic           rst_n,
  input  logic           in_valid,
  output logic           in_ready,
  input  logic [IDW-1:0] in_id,
  output logic           take,        // the core's in_valid: an input transfer
  input  logic           core_valid,  // the core's out_valid
  input  logic [W-1:0]   core_data,
  output logic           out_valid,
  input  logic           out_ready,
  output logic [W-1:0]   out_data,
  output logic [IDW-1:0] out_id
);
  localparam int AW = $clog2(DEPTH + 1);
  logic [W-1:0] mem [0:DEPTH-1];
  logic [IDW-1:0] ids [0:DEPTH-1];  // in input order; the head belongs to the FIFO's head
  logic [AW-1:0] rp, wp, ip, count, inflight;
  assign take = in_valid && in_ready;
  // the queue's head (q_*), then the ports: directly, or through raypipe_stream_swap
  logic q_valid, q_ready;
  logic [W-1:0] q_data;
  logic [IDW-1:0] q_id;
  wire pop = q_valid && (q_ready
`ifdef RAYPIPE_FAULT_STREAM_DROP
                         || 1'b1
`endif
                        );
  assign q_valid = count != 0;
  assign in_ready = rst_n && (inflight + count < DEPTH);
  always @(posedge clk) begin
    if (!rst_n) begin
      rp <= '0;
      wp <= '0;
      ip <= '0;
      count <= '0;
      inflight <= '0;
    end else begin
      if (take) begin
        ids[ip] <= in_id;
        ip <= (ip == DEPTH - 1) ? '0 : ip + 1'b1;
      end
      if (core_valid) begin
        mem[wp] <= core_data;
        wp <= (wp == DEPTH - 1) ? '0 : wp + 1'b1;
      end
      if (pop) rp <= (rp == DEPTH - 1) ? '0 : rp + 1'b1;
      count <= count + AW'(core_valid) - AW'(pop);
      inflight <= inflight + AW'(take) - AW'(core_valid);
    end
  end
  always @* begin
    q_data = mem[rp];
    q_id = ids[rp];
  end
`ifdef RAYPIPE_STREAM_SWAP
  raypipe_stream_swap #(.W(W + IDW)) swap (
    .clk(clk), .rst_n(rst_n), .in_valid(q_valid), .in_ready(q_ready), .in_data({q_data, q_id}),
    .out_valid(out_valid), .out_ready(out_ready), .out_data({out_data, out_id}));
`else
  assign out_valid = q_valid;
  assign q_ready = out_ready;
  assign {out_data, out_id} = {q_data, q_id};
`endif
endmodule

module raypipe_stream_swap #(
  parameter int W = 1
) (
  input  logic         clk,
  input  logic         rst_n,
  input  logic         in_valid,
  output logic         in_ready,
  input  logic [W-1:0] in_data,
  output logic         out_valid,
  input  logic         out_ready,
  output logic [W-1:0] out_data
);
  // state: 0 empty; 1 a held, waiting for b (alone after 8 cycles); 2 offering b; 3 offering a
  logic [1:0] st;
  logic [3:0] age;
  logic [W-1:0] a, b;
  wire alone = st == 2'd1 && age >= 4'd8;
  assign in_ready = rst_n && (st == 2'd0 || (st == 2'd1 && !alone));
  assign out_valid = st == 2'd2 || st == 2'd3 || alone;
  assign out_data = st == 2'd2 ? b : a;
  always @(posedge clk) begin
    if (!rst_n) begin
      st <= 2'd0;
      age <= '0;
    end else begin
      case (st)
        2'd0: if (in_valid && in_ready) begin
          a <= in_data;
          age <= '0;
          st <= 2'd1;
        end
        2'd1: if (alone) begin
          if (out_ready) st <= 2'd0;
        end else if (in_valid && in_ready) begin
          b <= in_data;
          st <= 2'd2;
        end else age <= age + 1'b1;
        2'd2: if (out_ready) st <= 2'd3;
        default: if (out_ready) st <= 2'd0;
      endcase
    end
  end
endmodule

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
`ifdef RAYPIPE_ID_W
  ,
  input  logic [`RAYPIPE_ID_W-1:0] in_id,
  output logic [`RAYPIPE_ID_W-1:0] out_id
`endif
);
`ifdef RAYPIPE_ID_W
  localparam int IDW = `RAYPIPE_ID_W;
`else
  localparam int IDW = 1;
  wire [IDW-1:0] in_id = '0;
  wire [IDW-1:0] out_id;
`endif
  logic take, core_valid;
  logic [OUT_W-1:0] core_out;
  logic [STG_W-1:0] core_stg;
  `CORE core (.clk(clk), .rst_n(rst_n), .in_valid(take), .in_row(in_row), .out_valid(core_valid),
              .out_row(core_out), .stg_row(core_stg));
  raypipe_stream_fifo #(.W(OUT_W + STG_W), .IDW(IDW), .DEPTH(DEPTH)) fifo (
    .clk(clk), .rst_n(rst_n), .in_valid(in_valid), .in_ready(in_ready), .in_id(in_id), .take(take),
    .core_valid(core_valid), .core_data({core_out, core_stg}), .out_valid(out_valid), .out_ready(out_ready),
    .out_data({out_row, stg_row}), .out_id(out_id));
endmodule
