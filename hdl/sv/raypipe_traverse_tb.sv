// raypipe HDL kit: the testbench of the traverse unit.
//
// Writes the set's tree images (tree_root.hex, tree_l<k>_left/right.hex) into the DUT through
// its write port, streams the rays of traverse_rays.hex with a valid/ready handshake, and
// compares each result (in ray order) with traverse_expected.hex: the first-N leaf ids, their
// count, the passes, the box tests and each level's final history state. Prints
// `N passed, M failed`; any failure ends the run with $fatal. A ray with no result within
// its timeout is reported as a hang (ray, class and cycle), counted failed, and the DUT is
// reset and given its tree again; the rays after it are still driven and checked. The timeout
// of a ray (cycles since the previous result) is derived from the set: 16 x (the ray's expected
// box tests + 2 x the tree's levels) + 256 cycles — room for a DUT that spends 8 cycles per box
// test and tests twice as many boxes as the model counts, plus a pass down the tree and back —
// so a DUT that hangs costs little per ray; +timeout=CYCLES fixes it for every ray instead.
// The DUT is the module named by the DUT macro (default raypipe_traverse_ref), with the ports
// of hdl/sv/ref/traverse_ref.sv. Plusargs: +set=DIR, +maxerrors=K, +timeout=CYCLES (per ray),
// +strict.
`ifndef DUT
`define DUT raypipe_traverse_ref
`endif
module raypipe_traverse_tb;
  import raypipe_set_pkg::*;

  logic clk = 1'b0;
  logic rst_n = 1'b0;
  logic wr_en = 1'b0;
  logic [7:0] wr_level = '0;
  logic wr_right = 1'b0;
  logic [31:0] wr_row = '0;
  logic [ENTRY_W-1:0] wr_data = '0;
  logic ray_valid = 1'b0;
  logic ray_ready;
  logic [IN_W-1:0] ray_row = '0;
  logic res_valid;
  logic [OUT_W-1:0] res_row;

  logic [IN_W-1:0] ins [0:N-1];
  logic [OUT_W-1:0] outs [0:N-1];
  logic [ENTRY_W-1:0] img [0:TOTAL_ROWS-1];

  `DUT dut (.clk(clk), .rst_n(rst_n), .wr_en(wr_en), .wr_level(wr_level), .wr_right(wr_right), .wr_row(wr_row),
            .wr_data(wr_data), .ray_valid(ray_valid), .ray_ready(ray_ready), .ray_row(ray_row), .res_valid(res_valid),
            .res_row(res_row));

  always #5 clk = ~clk;

  string dir;
  int max_errors = 10;
  bit strict = 0;
  int timeout = -1;  // +timeout: fixed per ray; -1: derived per ray (budget)
  int sent = 0;
  int got = 0;
  int passed = 0;
  int failed = 0;
  int idle = 0;
  int cycle = 0;
  int hangs = 0;
  logic took = 1'b0;

  always @(posedge clk) cycle <= cycle + 1;

  // the cycles ray k may take after the previous result (see the header)
  int longest;
  function automatic int budget(int k);
    if (timeout >= 0) return timeout;
    return 16 * (int'(outs[k][BOX_TESTS_LSB +: BOX_TESTS_W]) + 2 * int'(LEVELS)) + 256;
  endfunction

  task automatic write_entry(input logic [7:0] level, input logic right, input int row, input logic [ENTRY_W-1:0] e);
    @(negedge clk);
    wr_en = 1'b1;
    wr_level = level;
    wr_right = right;
    wr_row = row;
    wr_data = e;
  endtask

  // writes the set's tree images through the DUT's write port
  task automatic load_tree();
    $readmemh($sformatf("%0s/tree_root.hex", dir), img, 0, 0);
    write_entry(8'hff, 1'b0, 0, img[0]);
    for (int l = 0; l < int'(LEVELS); l++) begin
      for (int side = 0; side < 2; side++) begin
        $readmemh($sformatf("%0s/tree_l%0d_%0s.hex", dir, l, side ? "right" : "left"), img, 0, level_rows(l) - 1);
        for (int k = 0; k < level_rows(l); k++) write_entry(l[7:0], side[0], k, img[k]);
      end
    end
    @(negedge clk);
    wr_en = 1'b0;
  endtask

  initial begin
    if (!$value$plusargs("set=%s", dir)) dir = "set";
    if ($value$plusargs("maxerrors=%d", max_errors)) ;
    if ($value$plusargs("timeout=%d", timeout)) ;
    // +strict also compares passes and box_tests (implementation-defined)
    if ($test$plusargs("strict")) strict = 1;
    $readmemh($sformatf("%0s/%0s", dir, IN_FILE), ins);
    $readmemh($sformatf("%0s/%0s", dir, OUT_FILE), outs);
    longest = 0;
    for (int k = 0; k < N; k++) if (budget(k) > longest) longest = budget(k);
    if (timeout >= 0)
      $display("raypipe_traverse_tb: %0d rays from %0s, %0d levels, first %0d leaves, timeout %0d cycles per ray", N, dir, LEVELS, LEAVES, timeout);
    else
      $display("raypipe_traverse_tb: %0d rays from %0s, %0d levels, first %0d leaves, timeout 16 x (expected box tests + %0d) + 256 cycles per ray (longest %0d)",
               N, dir, LEVELS, LEAVES, 2 * LEVELS, longest);
    repeat (2) @(negedge clk);
    rst_n = 1'b1;
    load_tree();
    // stream the rays from `got` on: a ray driven while ray_ready is high is taken at the next
    // rising edge; a ray with no result within the timeout is a hang: report it, reset the
    // DUT, load its tree again and go on from the next ray
    while (got < N) begin
      sent = got;
      took = 1'b0;
      ray_valid = 1'b0;
      idle = 0;
      while (got < N && idle < budget(got)) begin
        if (ray_valid && took) sent = sent + 1;
        if (sent < N) begin
          ray_valid = 1'b1;
          ray_row = ins[sent];
          took = ray_ready;
        end else ray_valid = 1'b0;
        @(negedge clk);
      end
      if (got < N) begin
        failed++;
        hangs++;
        if (failed <= max_errors)
          $display("FAIL ray %0d (line %0d, class %0d %0s): no result within %0d cycles, a hang (at edge %0d); the DUT is reset and the next rays are checked",
                   got, got + 1, ins[got][IN_W-1 -: 8], class_name(ins[got][IN_W-1 -: 8]), budget(got), cycle);
        got++;
        ray_valid = 1'b0;
        rst_n = 1'b0;
        repeat (2) @(negedge clk);
        rst_n = 1'b1;
        load_tree();
      end
    end
    if (hangs > 0) $display("%0d rays hung", hangs);
    $display("%0d passed, %0d failed", passed, failed);
    if (failed > 0) $fatal(1, "raypipe_traverse_tb: %0d of %0d rays failed", failed, N);
    $finish;
  end

  always @(negedge clk) begin
    idle = idle + 1;
    if (rst_n && res_valid) begin
      idle = 0;
      if (got >= N) begin
        $display("FAIL: a result with no ray outstanding");
        failed++;
      end else begin
        if (diff_out(res_row, outs[got], strict) != "none") begin
          failed++;
          if (failed <= max_errors)
            $display("FAIL ray %0d (line %0d, class %0d %0s): first field to differ: %0s", got, got + 1,
                     ins[got][IN_W-1 -: 8], class_name(ins[got][IN_W-1 -: 8]), diff_out(res_row, outs[got], strict));
        end else passed++;
        got++;
      end
    end
  end
`define RAYPIPE_WAVES_TOP raypipe_traverse_tb
`include "raypipe_waves.svh"
endmodule
