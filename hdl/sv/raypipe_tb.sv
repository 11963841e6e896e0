// raypipe HDL kit: the testbench for every unit (rti, slab, op).
//
// It reads a vector set written by `raypipe vectors` (its raypipe_pkg.sv must be compiled in
// first), drives one vector per clock into the DUT (with an idle cycle every +gap=K cycles,
// default 5; +gap=0 streams back to back), and expects each vector's result exactly LATENCY
// clock edges after the edge that captured it, in order. It compares every output field and,
// unless +nostages, every stage signal, names the first field that differs (earliest stage
// first) and the vector's class, and prints `N passed, M failed`. The valid timing is checked
// cycle by cycle: an out_valid pulse where no vector is due is reported as an extra pulse at
// that cycle (no vector is consumed), a due vector without out_valid as a missing pulse for
// that vector at that cycle; every vector is counted once. Any failure ends the run with
// $fatal (non-zero exit status).
//
// The DUT is the module named by the DUT macro (default: the reference model of the unit),
// with this port list (widths from raypipe_set_pkg; rows are packed exactly as the .hex lines):
//   input  logic clk, rst_n (synchronous, active low), in_valid,
//   input  logic [IN_W-1:0]  in_row      one line of <unit>_inputs.hex
//   output logic             out_valid
//   output logic [OUT_W-1:0] out_row     one line of <unit>_expected.hex
//   output logic [STG_W-1:0] stg_row     one line of <unit>_stages.hex (tie to 0 and run +nostages if you have no probes)
// Plusargs: +set=DIR (default "set"), +gap=K, +nostages, +maxerrors=K (default 10), +latency=K
// (your DUT's latency, when it is not the manifest's one stage per table stage).
`ifndef DUT
`define DUT raypipe_ref
`endif
module raypipe_tb;
  import raypipe_set_pkg::*;

  logic clk = 1'b0;
  logic rst_n = 1'b0;
  logic in_valid = 1'b0;
  logic [IN_W-1:0] in_row = '0;
  logic out_valid;
  logic [OUT_W-1:0] out_row;
  logic [STG_W-1:0] stg_row;

  logic [IN_W-1:0] ins [0:N-1];
  logic [OUT_W-1:0] outs [0:N-1];
  logic [STG_W-1:0] stgs [0:N-1];
  int sent_at [0:N-1];

  `DUT dut (.clk(clk), .rst_n(rst_n), .in_valid(in_valid), .in_row(in_row), .out_valid(out_valid),
            .out_row(out_row), .stg_row(stg_row));

  always #5 clk = ~clk;

  string dir;
  int gap = 5;
  int check_stages = 1;
  int max_errors = 10;
  bit strict = 0;
  int lat = LATENCY;
  int cycle = 0;
  int sent = 0;
  int got = 0;
  int passed = 0;
  int failed = 0;
  int extra = 0;


  always @(posedge clk) cycle <= cycle + 1;

  initial begin
    if (!$value$plusargs("set=%s", dir)) dir = "set";
    if ($value$plusargs("gap=%d", gap)) ;
    if ($value$plusargs("maxerrors=%d", max_errors)) ;
    if ($value$plusargs("latency=%d", lat)) ;
    if ($test$plusargs("nostages") || !HAS_STAGES) check_stages = 0;
    // +strict also compares the fields the manifest marks implementation-defined
    if ($test$plusargs("strict")) strict = 1;
    $readmemh($sformatf("%0s/%0s", dir, IN_FILE), ins);
    $readmemh($sformatf("%0s/%0s", dir, OUT_FILE), outs);
    if (HAS_STAGES) $readmemh($sformatf("%0s/%0s", dir, STG_FILE), stgs);
    $display("raypipe_tb: unit %s, %0d vectors from %s, latency %0d, stages %0s", UNIT, N, dir, lat,
             check_stages ? "checked" : "not checked");
    repeat (2) @(negedge clk);
    rst_n = 1'b1;
    // drive at the negative edge; the DUT captures at the next positive edge
    while (sent < N) begin
      @(negedge clk);
      if (gap > 0 && (cycle % gap) == gap - 1) begin
        in_valid = 1'b0;
        in_row = '0;
      end else begin
        in_valid = 1'b1;
        in_row = ins[sent];
        sent_at[sent] = cycle + 1;
        sent = sent + 1;
      end
    end
    @(negedge clk);
    in_valid = 1'b0;
    in_row = '0;
    repeat (lat + 4) @(negedge clk);
    if (got < N) begin
      $display("FAIL: %0d vectors were never driven or due (the first: vector %0d, line %0d)", N - got, got, got + 1);
      failed += N - got;
    end
    if (extra > 0) $display("%0d extra out_valid pulses", extra);
    $display("%0d passed, %0d failed", passed, failed);
    if (failed > 0) $fatal(1, "raypipe_tb: %0d of %0d vectors failed", failed, N);
    $finish;
  end

  // compare at the negative edge what the last positive edge produced; vector `got` is due at
  // edge sent_at[got] + lat
  logic due;
  always @(negedge clk) begin
    if (rst_n) begin
      due = got < sent && cycle == sent_at[got] + lat;
      if (out_valid && !due) begin
        failed++;
        extra++;
        if (failed <= max_errors && got < sent)
          $display("FAIL: extra out_valid pulse at edge %0d: no vector is due (next due: vector %0d at edge %0d)", cycle,
                   got, sent_at[got] + lat);
        else if (failed <= max_errors)
          $display("FAIL: extra out_valid pulse at edge %0d: no vector is due (none outstanding)", cycle);
      end else if (due && !out_valid) begin
        failed++;
        if (failed <= max_errors)
          $display("FAIL vector %0d (line %0d, class %0d %0s): missing out_valid pulse at edge %0d (%0d edges after the edge that captured it)",
                   got, got + 1, ins[got][IN_W-1 -: 8], class_name(ins[got][IN_W-1 -: 8]), cycle, lat);
        got++;
      end else if (due) begin
        if (diff_out(out_row, outs[got], strict) != "none" || (check_stages && diff_stg(stg_row, stgs[got], outs[got], strict) != "none"))
        begin
          failed++;
          if (failed <= max_errors && check_stages)
            $display("FAIL vector %0d (line %0d, class %0d %0s): first output to differ: %0s; first stage signal to differ: %0s",
                     got, got + 1, ins[got][IN_W-1 -: 8], class_name(ins[got][IN_W-1 -: 8]), diff_out(out_row, outs[got], strict),
                     diff_stg(stg_row, stgs[got], outs[got], strict));
          else if (failed <= max_errors)
            $display("FAIL vector %0d (line %0d, class %0d %0s): first output to differ: %0s (stages not checked)",
                     got, got + 1, ins[got][IN_W-1 -: 8], class_name(ins[got][IN_W-1 -: 8]), diff_out(out_row, outs[got], strict));
        end else passed++;
        got++;
      end
    end
  end
`define RAYPIPE_WAVES_TOP raypipe_tb
`include "raypipe_waves.svh"
endmodule
