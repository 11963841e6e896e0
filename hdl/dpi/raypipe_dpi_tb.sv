// raypipe HDL kit: a constrained-random testbench scored by the live model through DPI-C.
//
// It drives the DUT (the rti or slab unit of the compiled raypipe_pkg.sv, which fixes the
// format and the row layout; by default the unit's reference DUT) with +n=N random vectors,
// one per clock, and scores every output and every stage signal against raypipe's model,
// called through hdl/dpi/raypipe_dpi.sv for each vector as it is driven. No vector file is
// read. Stimulus (seeded by +seed=S), per vector:
//   45 %  aimed: a random triangle (box) in [-1, 1]^3, an origin in [-2, 2]^3, the direction
//         towards a random point of it (hits and grazes);
//   15 %  random geometry (mostly misses);
//   30 %  edges: an aimed vector with one to three inputs replaced by an edge encoding (±0,
//         ±inf, NaN with a random sign and payload, quiet or signalling, subnormals, the
//         least and largest subnormal, ±min normal, ±max);
//   10 %  ties: products that land exactly halfway between two neighbours (rti: dy·e2z with
//         dy = 1 + 2^-k and e2z = 1 + 2^-(M+1-k); slab: (max - o)·(1/d) the same way).
// Each result must come LATENCY edges after the edge that captured its vector. The care rules
// of the set package (diff_out, diff_stg) apply. It prints `N passed, M failed`, and ends with
// $fatal when a vector failed.
// Valid/ready (compiled with RAYPIPE_DPI_HANDSHAKE; hdl/dpi/run --handshake or --hardfloat): the
// DUT has the ports of hdl/sv/raypipe_stream_tb.sv (in_ready, out_ready besides); each vector is
// held on in_row with in_valid until in_ready takes it, out_ready is low in a seeded +stall=P
// percent of the cycles, results are expected in input order at any latency, a result offered
// without out_ready must stay unchanged until its transfer (else a protocol failure), and the
// oldest vector without a result for 4 x +latency=L (default LATENCY) + 64 ready cycles fails the
// run, named. Latency min / median / max and the throughput are printed.
// Plusargs: +format=F (must be the package's format), +options=O (the unit's CLI options, ','
// for ' '), +n=N (default 2000), +seed=S (default 1), +maxerrors=K (default 10); with the
// handshake +stall=P (default 0), +latency=L.
`ifndef DUT
`define DUT raypipe_ref
`endif
module raypipe_dpi_tb;
  import raypipe_set_pkg::*;
  import raypipe_dpi::*;

  localparam int W = int'(WIDTH);
  localparam int E = int'(EXP);
  localparam int M = int'(MAN);
  localparam int NI = (IN_W - 8) / W;

  logic clk = 1'b0;
  logic rst_n = 1'b0;
  logic in_valid = 1'b0;
  logic [IN_W-1:0] in_row = '0;
  logic out_valid;
  logic [OUT_W-1:0] out_row;
  logic [STG_W-1:0] stg_row;

`ifdef RAYPIPE_DPI_HANDSHAKE
  logic in_ready;
  logic out_ready = 1'b0;
  `DUT dut (.clk(clk), .rst_n(rst_n), .in_valid(in_valid), .in_ready(in_ready), .in_row(in_row), .out_valid(out_valid),
            .out_ready(out_ready), .out_row(out_row), .stg_row(stg_row));
`else
  `DUT dut (.clk(clk), .rst_n(rst_n), .in_valid(in_valid), .in_row(in_row), .out_valid(out_valid),
            .out_row(out_row), .stg_row(stg_row));
`endif

  always #5 clk = ~clk;

  chandle u;
  longint unsigned no, ns;
  int unsigned ow [RP_MAX_OUT];
  int unsigned sw [RP_MAX_STG];
  int cycle = 0;
  int passed = 0;
  int failed = 0;
  int max_errors = 10;
  // the expected rows of the vectors in flight, oldest first
  logic [OUT_W-1:0] want_out [$];
  logic [STG_W-1:0] want_stg [$];
  int due_at [$];
  string kind_of [$];

  always @(posedge clk) cycle <= cycle + 1;

  // ---- stimulus ----
  function automatic real rnd(real lo, real hi);
    return lo + (hi - lo) * (real'($urandom()) / 4294967296.0);
  endfunction

  function automatic longint unsigned enc(real x);
    longint unsigned b;
    if (rp_encode(u, x, b) != RP_OK) $fatal(1, "rp_encode: %s", rp_last_error());
    return b;
  endfunction

  function automatic longint unsigned frac_bits();
    longint unsigned f = {$urandom(), $urandom()};
    return f & ((64'd1 << M) - 1);
  endfunction

  // an edge encoding of the format
  function automatic longint unsigned edge_value();
    longint unsigned s = longint'($urandom_range(0, 1)) << (W - 1);
    longint unsigned top = (64'd1 << E) - 1;
    case ($urandom_range(0, 9))
      0: return s;
      1: return s | (top << M);
      2: return s | (top << M) | (frac_bits() | 64'd1);
      3: return s | (frac_bits() | 64'd1);
      4: return s | ((top - 1) << M) | ((64'd1 << M) - 1);
      5: return s | (64'd1 << M);
      6: return s | ((64'd1 << M) - 1);
      7: return s | 64'd1;
      8: return s | (top << M) | (64'd1 << (M - 1));
      default: return s | (longint'($urandom_range(1, int'(top) - 1)) << M) | frac_bits();
    endcase
  endfunction

  // 1 + 2^-k and 1 + 2^-(M+1-k): their product is a tie between two neighbours
  function automatic void tie_pair(output real a, output real b);
    int k = $urandom_range(1, M);
    a = 1.0 + 2.0 ** (-k);
    b = 1.0 + 2.0 ** (-(M + 1 - k));
  endfunction

  // one vector's inputs (encodings, in the unit's input order) and its stimulus kind
  function automatic void stimulus(output longint unsigned v [RP_MAX_IN], output string kind);
    real x [RP_MAX_IN];
    real p [3], o [3], c [3], h [3];
    real a, b, r1, r2;
    int mode = $urandom_range(0, 99);
    kind = mode < 45 ? "aimed" : mode < 60 ? "random" : mode < 90 ? "edge" : "tie";
    for (int i = 0; i < 3; i++) o[i] = rnd(-2.0, 2.0);
    if (NI == 17) begin
      // rti: o, d, tmin, tmax, v0, v1, v2
      for (int i = 0; i < 9; i++) x[8 + i] = rnd(-1.0, 1.0);
      r1 = rnd(0.0, 1.0);
      r2 = rnd(0.0, 1.0 - r1);
      for (int i = 0; i < 3; i++) p[i] = x[8 + i] + r1 * (x[11 + i] - x[8 + i]) + r2 * (x[14 + i] - x[8 + i]);
      for (int i = 0; i < 3; i++) x[i] = o[i];
      for (int i = 0; i < 3; i++) x[3 + i] = kind == "random" ? rnd(-1.0, 1.0) : p[i] - o[i];
      x[6] = 0.0;
      x[7] = rnd(0.5, 4.0);
      if (kind == "tie") begin
        tie_pair(a, b);
        x[4] = a;  // dy
        x[10] = 0.0;  // v0z
        x[16] = b;  // v2z: e2z = b
      end
    end else begin
      // slab: o, d, tmin, tmax, box min, box max
      for (int i = 0; i < 3; i++) begin
        c[i] = rnd(-1.0, 1.0);
        h[i] = rnd(0.01, 0.5);
        x[8 + i] = c[i] - h[i];
        x[11 + i] = c[i] + h[i];
        p[i] = c[i] + rnd(-1.0, 1.0) * h[i];
        x[i] = o[i];
        x[3 + i] = kind == "random" ? rnd(-1.0, 1.0) : p[i] - o[i];
      end
      x[6] = 0.0;
      x[7] = rnd(0.5, 4.0);
      if (kind == "tie") begin
        // (max - o) * (1/d) with max - o = a and 1/d = b exactly (d = 1/b rounds, and so may 1/d:
        // the tie is then near, not at, the product)
        tie_pair(a, b);
        x[0] = 0.0;
        x[11] = a;
        x[8] = -a;
        x[3] = 1.0 / b;
      end
    end
    for (int i = 0; i < NI; i++) v[i] = enc(x[i]);
    if (kind == "edge") begin
      int k = $urandom_range(1, 3);
      for (int j = 0; j < k; j++) v[$urandom_range(0, NI - 1)] = edge_value();
    end
  endfunction

  // ---- the live model ----
  task automatic expect_rows(input longint unsigned v [RP_MAX_IN], input string kind);
    longint unsigned out [RP_MAX_OUT];
    longint unsigned stg [RP_MAX_STG];
    logic [OUT_W-1:0] ro;
    logic [STG_W-1:0] rs;
    int pos;
    if (rp_eval(u, v, longint'(NI), out, no, stg, ns) != RP_OK) $fatal(1, "rp_eval: %s", rp_last_error());
    if (cov != null && rp_cover_add(cov, v, longint'(NI)) != RP_OK) $fatal(1, "rp_cover_add: %s", rp_last_error());
    ro = '0;
    pos = OUT_W;
    for (int i = 0; i < int'(no); i++)
      for (int b = int'(ow[i]) - 1; b >= 0; b--) begin
        pos--;
        ro[pos] = out[i][b];
      end
    rs = '0;
    pos = STG_W;
    for (int i = 0; i < int'(ns); i++)
      for (int b = int'(sw[i]) - 1; b >= 0; b--) begin
        pos--;
        rs[pos] = stg[i][b];
      end
    want_out.push_back(ro);
    want_stg.push_back(rs);
    kind_of.push_back(kind);
  endtask

  // +cover=FILE: the driven rows' functional coverage, written to FILE at the end
  chandle cov = null;
  string cover_path;

  initial begin
    string fmt, opts, o;
    int n = 2000, seed = 1, rc, bits;
    longint unsigned v [RP_MAX_IN];
    string kind;
    if (!$value$plusargs("format=%s", fmt)) $fatal(1, "raypipe_dpi_tb: give +format=F (the package's format)");
    if (!$value$plusargs("options=%s", o)) o = "";
    opts = "";
    for (int i = 0; i < o.len(); i++) opts = {opts, o[i] == "," ? " " : string'(o[i])};
    if ($value$plusargs("n=%d", n)) ;
    if ($value$plusargs("seed=%d", seed)) ;
    if ($value$plusargs("maxerrors=%d", max_errors)) ;
    void'($urandom(seed));
    rc = rp_unit_new(UNIT, fmt, opts, u);
    if (rc != RP_OK) $fatal(1, "rp_unit_new(%s, %s, \"%s\") = %0d: %s", UNIT, fmt, opts, rc, rp_last_error());
    if ($value$plusargs("cover=%s", cover_path)) begin
      rc = rp_cover_new(UNIT, fmt, opts, cov);
      if (rc != RP_OK) $fatal(1, "rp_cover_new(%s, %s, \"%s\") = %0d: %s", UNIT, fmt, opts, rc, rp_last_error());
    end
    if (rp_unit_width(u) != W || rp_unit_inputs(u) != longint'(NI))
      $fatal(1, "the live model (%s, %0d bits, %0d inputs) is not the package's format (%0d bits, %0d inputs)", fmt,
             rp_unit_width(u), rp_unit_inputs(u), W, NI);
    no = rp_unit_outputs(u);
    ns = rp_unit_stages(u);
    bits = 0;
    for (int i = 0; i < int'(no); i++) begin
      ow[i] = rp_unit_output_width(u, longint'(i));
      bits += int'(ow[i]);
    end
    if (bits != OUT_W) $fatal(1, "the live model's output row is %0d bits, the package's %0d", bits, OUT_W);
    bits = 0;
    for (int i = 0; i < int'(ns); i++) begin
      sw[i] = rp_unit_stage_width(u, longint'(i));
      bits += int'(sw[i]);
    end
    if (bits != STG_W) $fatal(1, "the live model's stage row is %0d bits, the package's %0d", bits, STG_W);
    $display("raypipe_dpi_tb: raypipe %s, unit %s, format %s, options \"%s\", %0d random vectors, seed %0d, latency %0d",
             rp_version(), UNIT, fmt, opts, n, seed, LATENCY);
    repeat (2) @(negedge clk);
    rst_n = 1'b1;
`ifdef RAYPIPE_DPI_HANDSHAKE
    if ($value$plusargs("stall=%d", stall)) ;
    if ($value$plusargs("latency=%d", lat)) ;
    if (stall < 0 || stall > 99) $fatal(1, "raypipe_dpi_tb: +stall=%0d: give a percentage from 0 to 99", stall);
    timeout = 4 * lat + 64;
    $display("raypipe_dpi_tb: valid/ready, stall %0d%%, timeout %0d ready cycles", stall, timeout);
    @(negedge clk);
    for (int k = 0; k < n && !hung; k++) begin
      stimulus(v, kind);
      in_row = '0;
      for (int i = 0; i < NI; i++)
        for (int b = 0; b < W; b++) in_row[IN_W - 9 - i * W - (W - 1 - b)] = v[i][b];
      in_valid = 1'b1;
      expect_rows(v, kind);
      // held until a rising edge with in_ready takes it
      do @(negedge clk); while (!took_in && !hung);
      in_at.push_back(took_at);
      sent++;
    end
    in_valid = 1'b0;
    wait (hung || got == sent);
    repeat (8) @(negedge clk);
    if (got < n) begin
      $display("FAIL: %0d vectors never came out", n - got);
      failed += n - got;
    end
    if (got > 0) begin
      lats.sort();
      $display("latency (edges from input to output transfer): min %0d, median %0d, max %0d over %0d results; throughput %0d results in %0d edges (%0.3f per clock)",
               lat_min, lats[lats.size() / 2], lat_max, got, got, last_out - first_in + 1, real'(got) / real'(last_out - first_in + 1));
    end
    if (proto > 0) $display("%0d protocol violations", proto);
`else
    for (int k = 0; k < n; k++) begin
      @(negedge clk);
      stimulus(v, kind);
      in_row = '0;
      for (int i = 0; i < NI; i++)
        for (int b = 0; b < W; b++) in_row[IN_W - 9 - i * W - (W - 1 - b)] = v[i][b];
      in_valid = 1'b1;
      expect_rows(v, kind);
      due_at.push_back(cycle + 1 + LATENCY);
    end
    @(negedge clk);
    in_valid = 1'b0;
    repeat (LATENCY + 4) @(negedge clk);
    if (due_at.size() > 0) begin
      $display("FAIL: %0d vectors never came out", due_at.size());
      failed += due_at.size();
    end
`endif
    $display("%0d passed, %0d failed", passed, failed);
    if (cov != null) begin
      if (rp_cover_write(cov, cover_path) != RP_OK) $fatal(1, "rp_cover_write(%s): %s", cover_path, rp_last_error());
      $display("coverage: %0d driven rows recorded in %s (raypipe cover %s)", rp_cover_rows(cov), cover_path, cover_path);
      rp_cover_free(cov);
    end
    rp_unit_free(u);
    if (failed > 0) $fatal(1, "raypipe_dpi_tb: %0d of %0d vectors failed", failed, n);
    $finish;
  end

`ifdef RAYPIPE_DPI_HANDSHAKE
  // ---- valid/ready: output stalls, in-order scoring, the protocol rule, the timeout ----
  int stall = 0;
  int lat = LATENCY;
  int timeout;
  int sent = 0;
  int got = 0;
  int proto = 0;
  int waited = 0;
  bit hung = 0;
  int in_at [$];
  int lats [$];
  int lat_min = 1 << 30;
  int lat_max = 0;
  int first_in = -1;
  int last_out = 0;
  bit held = 0;
  logic [OUT_W-1:0] held_out;
  logic [STG_W-1:0] held_stg;
  always @(negedge clk) if (rst_n) out_ready <= (stall == 0) || ($urandom_range(0, 99) >= stall);
  logic took_in = 1'b0;
  int took_at;
  always @(posedge clk) begin
    took_in <= rst_n && in_valid && in_ready;
    took_at <= cycle;
  end
  always @(posedge clk) begin
    if (rst_n && !hung) begin
      if (held && (!out_valid || out_row !== held_out || stg_row !== held_stg)) begin
        proto++;
        failed++;
        if (failed <= max_errors)
          $display("FAIL: protocol at edge %0d: the result offered at the edge before (out_valid without out_ready) %0s before its transfer",
                   cycle, !out_valid ? "was withdrawn" : "changed");
      end
      held <= out_valid && !out_ready;
      held_out <= out_row;
      held_stg <= stg_row;
      if (out_valid && out_ready) begin
        waited = 0;
        if (want_out.size() == 0 || in_at.size() == 0) begin
          failed++;
          if (failed <= max_errors) $display("FAIL: a result at edge %0d with no vector outstanding", cycle);
        end else begin
          if (first_in < 0) first_in = in_at[0];
          lats.push_back(cycle - in_at[0]);
          if (cycle - in_at[0] < lat_min) lat_min = cycle - in_at[0];
          if (cycle - in_at[0] > lat_max) lat_max = cycle - in_at[0];
          last_out = cycle;
          if (diff_out(out_row, want_out[0], 0) != "none" || diff_stg(stg_row, want_stg[0], want_out[0], 0) != "none") begin
            failed++;
            if (failed <= max_errors)
              $display("FAIL (vector %0d, %0s vector, edge %0d): first output to differ: %0s; first stage signal to differ: %0s", got,
                       kind_of[0], cycle, diff_out(out_row, want_out[0], 0), diff_stg(stg_row, want_stg[0], want_out[0], 0));
          end else passed++;
          got++;
          void'(in_at.pop_front());
          void'(want_out.pop_front());
          void'(want_stg.pop_front());
          void'(kind_of.pop_front());
        end
      end else if (in_at.size() > 0 && out_ready) begin
        waited++;
        if (waited > timeout) begin
          failed++;
          $display("FAIL (vector %0d, %0s vector): never came out: no result for %0d ready cycles", got, kind_of[0], timeout);
          hung = 1;
        end
      end
    end
  end
`else
  // compare at the negative edge what the last positive edge produced
  always @(negedge clk) begin
    if (rst_n) begin
      if (out_valid && (due_at.size() == 0 || due_at[0] != cycle)) begin
        failed++;
        if (failed <= max_errors) $display("FAIL: out_valid at edge %0d, where no vector is due", cycle);
      end else if (due_at.size() > 0 && due_at[0] == cycle) begin
        if (!out_valid) begin
          failed++;
          if (failed <= max_errors) $display("FAIL: no out_valid at edge %0d, where a %0s vector is due", cycle, kind_of[0]);
        end else if (diff_out(out_row, want_out[0], 0) != "none" || diff_stg(stg_row, want_stg[0], want_out[0], 0) != "none") begin
          failed++;
          if (failed <= max_errors)
            $display("FAIL (%0s vector, edge %0d): first output to differ: %0s; first stage signal to differ: %0s", kind_of[0],
                     cycle, diff_out(out_row, want_out[0], 0), diff_stg(stg_row, want_stg[0], want_out[0], 0));
        end else passed++;
        void'(due_at.pop_front());
        void'(want_out.pop_front());
        void'(want_stg.pop_front());
        void'(kind_of.pop_front());
      end
    end
  end
`endif
endmodule
