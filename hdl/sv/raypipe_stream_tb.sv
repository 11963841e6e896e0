// raypipe HDL kit: the valid/ready testbench for the streaming units (rti, slab, op).
//
// It reads a vector set like raypipe_tb.sv and drives a DUT with a handshake on both sides
// (AXI4-Stream rules: a transfer happens at a rising edge where valid and ready are both 1; a
// source holds valid and its data until the transfer):
//   input side:  the testbench raises in_valid with the next row (one idle cycle every +gap=K
//                cycles, default 0: back to back) and holds it until the DUT's in_ready takes it;
//   output side: the testbench drives out_ready, low in a seeded random +stall=P percent of the
//                cycles (default 0), and takes a result at each edge with out_valid && out_ready.
// Results must come out in input order, at any latency; each is compared with the next expected
// row (every output field and, unless +nostages, every stage signal; the first field that
// differs is named, earliest stage first). The latency of each result (edges from the input
// transfer to the output transfer) is reported as min / median / max.
// Timeout: a vector that has been in the DUT for more than +timeout=K output-ready cycles
// (cycles with out_ready = 1; stalls do not count) fails the run, naming it. Default K =
// 4 x the latency (+latency=L, default the set's LATENCY) + 64.
// An out_valid while no vector is outstanding is an extra result. Protocol: once out_valid is 1
// at an edge without out_ready, it must stay 1 and out_row (stg_row when stages are checked,
// out_id) must stay the same until the transfer (AXI4-Stream's rule for a source); a change
// fails the run, naming the edge. Any failure ends the run with $fatal.
// Out of order: with the macro RAYPIPE_ID_W defined (hdl/run --ids W), the DUT has the ports
//   input logic [RAYPIPE_ID_W-1:0] in_id, output logic [RAYPIPE_ID_W-1:0] out_id
// the testbench gives vector k the id k mod 2^W with its input transfer and matches each
// result to the outstanding vector with that id, in any order; it keeps at most 2^W vectors
// outstanding (in_valid stays low while 2^W are), so an id names one vector. The timeout then
// applies to the oldest vector still outstanding, and the largest reordering (how many later
// vectors came out before one) is reported. Plusargs: +set=DIR, +gap=K, +stall=P, +seed=S (default 1), +latency=L, +timeout=K,
// +nostages, +maxerrors=K (default 10), +strict.
//
// The DUT is the module named by the DUT macro, with the ports of raypipe_tb.sv plus the two
// readies:
//   input  logic clk, rst_n (synchronous, active low)
//   input  logic in_valid,  output logic in_ready,  input  logic [IN_W-1:0]  in_row
//   output logic out_valid, input  logic out_ready, output logic [OUT_W-1:0] out_row,
//   output logic [STG_W-1:0] stg_row
`ifndef DUT
`define DUT raypipe_stream_ref
`endif
module raypipe_stream_tb;
  import raypipe_set_pkg::*;

  logic clk = 1'b0;
  logic rst_n = 1'b0;
  logic in_valid = 1'b0;
  logic in_ready;
  logic [IN_W-1:0] in_row = '0;
  logic out_valid;
  logic out_ready = 1'b0;
  logic [OUT_W-1:0] out_row;
  logic [STG_W-1:0] stg_row;
`ifdef RAYPIPE_ID_W
  localparam int IDN = 1 << `RAYPIPE_ID_W;
  logic [`RAYPIPE_ID_W-1:0] in_id = '0;
  logic [`RAYPIPE_ID_W-1:0] out_id;
`else
  localparam int IDN = 0;
`endif

  logic [IN_W-1:0] ins [0:N-1];
  logic [OUT_W-1:0] outs [0:N-1];
  logic [STG_W-1:0] stgs [0:N-1];
  int sent_at [0:N-1];
  int lats [0:N-1];
  bit rcvd [0:N-1];
  int low = 0;  // the oldest vector not yet out
  int reorder = 0;  // the largest number of later vectors out before one

  `DUT dut (.clk(clk), .rst_n(rst_n), .in_valid(in_valid), .in_ready(in_ready), .in_row(in_row),
            .out_valid(out_valid), .out_ready(out_ready), .out_row(out_row), .stg_row(stg_row)
`ifdef RAYPIPE_ID_W
            , .in_id(in_id), .out_id(out_id)
`endif
           );

  always #5 clk = ~clk;

  string dir;
  int gap = 0;
  int stall = 0;
  int seed = 1;
  int check_stages = 1;
  int max_errors = 10;
  bit strict = 0;
  int lat = LATENCY;
  int timeout = -1;
  int cycle = 0;
  int sent = 0;
  int got = 0;
  int passed = 0;
  int failed = 0;
  int extra = 0;
  int proto = 0;  // protocol violations
  int waited = 0;  // out_ready cycles the oldest outstanding vector has waited
  bit done = 0;

  always @(posedge clk) cycle <= cycle + 1;

  // the seeded stall pattern: out_ready is drawn at each negative edge
  int unsigned rng;
  function automatic int unsigned next_rand();
    rng = rng * 32'd1664525 + 32'd1013904223;
    return rng >> 8;
  endfunction

  initial begin
    if (!$value$plusargs("set=%s", dir)) dir = "set";
    if ($value$plusargs("gap=%d", gap)) ;
    if ($value$plusargs("stall=%d", stall)) ;
    if ($value$plusargs("seed=%d", seed)) ;
    if ($value$plusargs("maxerrors=%d", max_errors)) ;
    if ($value$plusargs("latency=%d", lat)) ;
    if (!$value$plusargs("timeout=%d", timeout)) timeout = 4 * lat + 64;
    if ($test$plusargs("nostages") || !HAS_STAGES) check_stages = 0;
    if ($test$plusargs("strict")) strict = 1;
    if (stall < 0 || stall > 99) $fatal(1, "raypipe_stream_tb: +stall=%0d: give a percentage from 0 to 99", stall);
    rng = seed;
    $readmemh($sformatf("%0s/%0s", dir, IN_FILE), ins);
    $readmemh($sformatf("%0s/%0s", dir, OUT_FILE), outs);
    if (HAS_STAGES) $readmemh($sformatf("%0s/%0s", dir, STG_FILE), stgs);
    $display("raypipe_stream_tb: unit %s, %0d vectors from %s, valid/ready, stall %0d%% (seed %0d), gap %0d, timeout %0d ready cycles, stages %0s",
             UNIT, N, dir, stall, seed, gap, timeout, check_stages ? "checked" : "not checked");
    repeat (2) @(negedge clk);
    rst_n = 1'b1;
    while (sent < N) begin
      @(negedge clk);
      if (in_valid && in_ready_seen) begin
        // the last edge took the row
        in_valid = 1'b0;
      end
      if (!in_valid && sent < N) begin
        if ((gap > 0 && (cycle % gap) == gap - 1) || (IDN > 0 && sent - low >= IDN)) begin
          in_row = '0;
        end else begin
          in_valid = 1'b1;
          in_row = ins[sent];
`ifdef RAYPIPE_ID_W
          in_id = sent[`RAYPIPE_ID_W-1:0];
`endif
        end
      end
    end
    wait (done);
    if (got < N) begin
      $display("FAIL: %0d vectors never came out (the first: vector %0d, line %0d)", N - got, low, low + 1);
      failed += N - got;
    end
    if (extra > 0) $display("%0d extra results", extra);
    if (got > 0) report_latency();
    $display("%0d passed, %0d failed", passed, failed);
    if (proto > 0) $fatal(1, "raypipe_stream_tb: %0d protocol violations (out_valid withdrawn or data changed before the transfer)", proto);
    if (failed > 0) $fatal(1, "raypipe_stream_tb: %0d of %0d vectors failed", failed, N);
    $finish;
  end

  // the input transfer at each rising edge
  logic in_ready_seen = 1'b0;
  always @(posedge clk) begin
    in_ready_seen <= 1'b0;
    if (rst_n && in_valid && in_ready) begin
      sent_at[sent] <= cycle;
      sent <= sent + 1;
      in_ready_seen <= 1'b1;
    end
  end

  // out_ready: low in stall % of the cycles
  always @(negedge clk) begin
    if (rst_n) out_ready <= (stall == 0) || ((next_rand() % 100) >= stall);
  end

  // the output transfer at each rising edge, scored at the next negative edge
  logic took = 1'b0;
  logic [OUT_W-1:0] took_out;
  logic [STG_W-1:0] took_stg;
  int took_id = 0;
  int took_at;
  always @(posedge clk) begin
    took <= rst_n && out_valid && out_ready;
    took_out <= out_row;
    took_stg <= stg_row;
`ifdef RAYPIPE_ID_W
    took_id <= int'(out_id);
`endif
    took_at <= cycle;
  end

  // the protocol: a result offered without ready is held, unchanged, until it is taken
  logic held = 1'b0;
  logic [OUT_W-1:0] held_out;
  logic [STG_W-1:0] held_stg;
  int held_id = 0;
`ifdef RAYPIPE_ID_W
  int cur_id;
  always @* cur_id = int'(out_id);
`else
  localparam int cur_id = 0;
`endif
  always @(posedge clk) begin
    if (rst_n && held && !done && (!out_valid || out_row !== held_out || cur_id != held_id
                                   || (check_stages && stg_row !== held_stg))) begin
      proto++;
      if (proto <= max_errors)
        $display("FAIL: protocol at edge %0d: the result offered at the edge before (out_valid without out_ready) %0s before its transfer (AXI4-Stream: a source holds valid and its data until the transfer)",
                 cycle, !out_valid ? "was withdrawn" : "changed");
    end
    held <= rst_n && out_valid && !out_ready;
    held_out <= out_row;
    held_stg <= stg_row;
    held_id <= cur_id;
  end

  // the vector a result belongs to: the oldest outstanding one, or (ids) the outstanding one
  // with its id; -1 when there is none
  function automatic int owner(int id);
    if (IDN == 0) return got < sent ? low : -1;
    for (int j = low; j < sent; j++)
      if (!rcvd[j] && (j % IDN) == id) return j;
    return -1;
  endfunction

  always @(negedge clk) begin
    if (rst_n && !done) begin
      if (took) begin
        k = owner(took_id);
        if (k < 0) begin
          failed++;
          extra++;
          if (failed <= max_errors && IDN > 0)
            $display("FAIL: extra result at edge %0d: no outstanding vector has id %0d", took_at, took_id);
          else if (failed <= max_errors)
            $display("FAIL: extra result at edge %0d: no vector is outstanding", took_at);
        end else begin
          lats[got] = took_at - sent_at[k];
          last_at = took_at;
          if (got - k > reorder) reorder = got - k;
          if (diff_out(took_out, outs[k], strict) != "none"
              || (check_stages && diff_stg(took_stg, stgs[k], outs[k], strict) != "none")) begin
            failed++;
            if (failed <= max_errors && check_stages)
              $display("FAIL vector %0d (line %0d, class %0d %0s): first output to differ: %0s; first stage signal to differ: %0s (result at edge %0d)",
                       k, k + 1, ins[k][IN_W-1 -: 8], class_name(ins[k][IN_W-1 -: 8]), diff_out(took_out, outs[k], strict),
                       diff_stg(took_stg, stgs[k], outs[k], strict), took_at);
            else if (failed <= max_errors)
              $display("FAIL vector %0d (line %0d, class %0d %0s): first output to differ: %0s (stages not checked; result at edge %0d)",
                       k, k + 1, ins[k][IN_W-1 -: 8], class_name(ins[k][IN_W-1 -: 8]), diff_out(took_out, outs[k], strict),
                       took_at);
          end else passed++;
          rcvd[k] = 1'b1;
          got++;
          if (k == low) waited = 0;
          while (low < sent && rcvd[low]) low++;
        end
      end else if (low < sent && out_ready) begin
        waited++;
        if (waited > timeout) begin
          $display("FAIL vector %0d (line %0d, class %0d %0s): never came out: no result for %0d ready cycles (it went in at edge %0d; +timeout=%0d)",
                   low, low + 1, ins[low][IN_W-1 -: 8], class_name(ins[low][IN_W-1 -: 8]), waited, sent_at[low], timeout);
          done = 1;
        end
      end
      // after the last result, 8 more cycles for extra results
      if (got == N) begin
        tail--;
        if (tail == 0) done = 1;
      end
    end
  end
  int k;
  int tail = 8;
  int last_at = 0;

  // min / median / max of the latencies of the results that came out
  task automatic report_latency;
    int lo, hi, c, k;
    int h [];
    lo = lats[0];
    hi = lats[0];
    for (k = 1; k < got; k++) begin
      if (lats[k] < lo) lo = lats[k];
      if (lats[k] > hi) hi = lats[k];
    end
    h = new[hi - lo + 1];
    for (k = 0; k <= hi - lo; k++) h[k] = 0;
    for (k = 0; k < got; k++) h[lats[k] - lo] = h[lats[k] - lo] + 1;
    c = 0;
    k = 0;
    while (2 * (c + h[k]) <= got) begin
      c = c + h[k];
      k++;
    end
    $display("latency (edges from input to output transfer): min %0d, median %0d, max %0d over %0d results", lo, lo + k, hi, got);
    if (IDN > 0) $display("out of order: ids of %0d bits; at most %0d later vector(s) came out before an earlier one", $clog2(IDN), reorder);
    $display("throughput: %0d results in %0d edges from the first input to the last output transfer (%0.3f per clock)", got,
             last_at - sent_at[0] + 1, real'(got) / real'(last_at - sent_at[0] + 1));
  endtask
`define RAYPIPE_WAVES_TOP raypipe_stream_tb
`define RAYPIPE_FAILURES (failed + proto)
`include "raypipe_waves.svh"
endmodule
