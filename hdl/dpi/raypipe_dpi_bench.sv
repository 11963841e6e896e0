// The per-call cost of the live model through DPI-C (hdl/dpi/run --bench): +n=N calls of
// rp_eval (one RTI or slab test with its stage signals), of rp_eval without stage signals, and
// of rp_unit_width (a call that does nothing: the DPI crossing alone), each timed by the
// wall clock ($realtime is simulation time; the runner reads the clock between phases).
module raypipe_dpi_bench;
  import raypipe_set_pkg::*;
  import raypipe_dpi::*;
  localparam int W = int'(WIDTH);
  localparam int NI = (IN_W - 8) / W;
  initial begin
    chandle u;
    string fmt;
    int n = 100000;
    longint unsigned v [RP_MAX_IN];
    longint unsigned out [RP_MAX_OUT];
    longint unsigned stg [RP_MAX_STG];
    longint unsigned no, ns, sink = 0;
    if (!$value$plusargs("format=%s", fmt)) fmt = "f32";
    if ($value$plusargs("n=%d", n)) ;
    if (rp_unit_new(UNIT, fmt, "", u) != RP_OK) $fatal(1, "%s", rp_last_error());
    no = rp_unit_outputs(u);
    ns = rp_unit_stages(u);
    for (int i = 0; i < NI; i++) void'(rp_encode(u, 0.25 * (i % 5) - 0.5, v[i]));
    $system("date +%s.%N > phase0");
    for (int k = 0; k < n; k++) begin
      v[0] = longint'(k) & ((64'd1 << (W - 2)) - 1);
      if (rp_eval(u, v, longint'(NI), out, no, stg, ns) != RP_OK) $fatal(1, "%s", rp_last_error());
      sink += out[0];
    end
    $system("date +%s.%N > phase1");
    for (int k = 0; k < n; k++) begin
      v[0] = longint'(k) & ((64'd1 << (W - 2)) - 1);
      if (rp_eval(u, v, longint'(NI), out, no, stg, 0) != RP_OK) $fatal(1, "%s", rp_last_error());
      sink += out[0];
    end
    $system("date +%s.%N > phase2");
    for (int k = 0; k < n; k++) sink += rp_unit_width(u);
    $system("date +%s.%N > phase3");
    $display("raypipe_dpi_bench: %0d calls each (sink %0d)", n, sink);
    $finish;
  end
endmodule
