// raypipe HDL kit: the waveform dump of the kit's SystemVerilog testbenches and the line that
// times their first failure (included inside the testbench module after `define
// RAYPIPE_WAVES_TOP <module name>; `define RAYPIPE_FAILURES <expression> when the failure count
// is not the module's `failed`).
// +wavefile=F dumps to F (FST with Icarus' -fst and Verilator's --trace-fst, as hdl/run builds
// them when it dumps: a Verilator build without --trace-fst writes nothing); with +waves_from=T0 [+waves_to=T1] only that window of simulation time. hdl/run passes
// them (+waves: the whole run; after a failure, a re-run dumps the window around the first
// failure, whose time the testbench prints as "first failure at simulation time T").
  string wavefile;
  int waves_from = -1;
  int waves_to = -1;
  initial begin
    if ($value$plusargs("wavefile=%s", wavefile)) begin
      $dumpfile(wavefile);
      $dumpvars(0, `RAYPIPE_WAVES_TOP);
      if ($value$plusargs("waves_from=%d", waves_from)) begin
        $dumpoff;
        #(waves_from) $dumpon;
        if ($value$plusargs("waves_to=%d", waves_to)) begin
          #(waves_to - waves_from) $dumpoff;
        end
      end
    end
  end
`ifndef RAYPIPE_FAILURES
`define RAYPIPE_FAILURES failed
`endif
  bit first_failure_shown = 0;
  always @(`RAYPIPE_FAILURES) begin
    if (`RAYPIPE_FAILURES > 0 && !first_failure_shown) begin
      first_failure_shown = 1;
      $display("first failure at simulation time %0t", $time);
    end
  end
