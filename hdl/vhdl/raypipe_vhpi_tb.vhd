-- raypipe HDL kit: the slab unit's reference DUT (hdl/vhdl/slab_ref.vhd) driven with random
-- stimulus and scored by the live model through VHPIDIRECT (hdl/vhdl/raypipe_vhpi.vhd), in
-- GHDL. The set package compiled before it (raypipe_pkg.vhd of a slab set of the format)
-- fixes the row layout. One vector per clock: aimed rays (50 %), random geometry (20 %), and
-- aimed rays with one to three inputs replaced by an edge encoding (30 %: ±0, ±inf, NaNs with
-- a random payload, subnormals, ±min normal, ±max). Every output and stage signal is compared
-- LATENCY edges after the edge that captured the vector; it prints `N passed, M failed` and
-- fails (severity failure) when a vector failed. Generics: FORMAT, OPTIONS (the unit's CLI
-- options), N (vectors), SEED.
-- HANDSHAKE = true: valid/ready (the DUT is raypipe_slab_stream, raypipe_stream.vhd, around the
-- reference): each vector is held with in_valid until in_ready takes it, out_ready is low in a
-- seeded STALL percent of the cycles, results are scored in input order at any latency, a result
-- offered without out_ready must stay unchanged until its transfer (else a protocol failure),
-- and the oldest vector without a result for 4 x (LATENCY + 2) + 64 ready cycles fails the run,
-- named; latency min / median / max are reported. DROP = true passes the wrapper's protocol bug.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use ieee.math_real.all;
use work.raypipe_slab_pkg.all;
use work.raypipe_vhpi.all;

entity raypipe_vhpi_tb is
  generic (
    FORMAT  : string := "f32";
    OPTIONS : string := "";
    N       : positive := 1000;
    SEED    : positive := 1;
    HANDSHAKE : boolean := false;
    STALL   : natural := 0;
    DROP    : boolean := false;
    -- a path: record the driven rows' functional coverage there (docs/coverage.md)
    COVER_FILE : string := ""
  );
end entity;

architecture sim of raypipe_vhpi_tb is
  constant W : natural := to_integer(unsigned(P_WIDTH(7 downto 0)));
  constant E : natural := to_integer(unsigned(P_EXP(7 downto 0)));
  constant M : natural := to_integer(unsigned(P_MAN(7 downto 0)));
  type out_arr is array (0 to N - 1) of std_logic_vector(SLAB_EXPECTED_W - 1 downto 0);
  type stg_arr is array (0 to N - 1) of std_logic_vector(SLAB_STAGES_W - 1 downto 0);

  signal clk : std_logic := '0';
  signal rst_n : std_logic := '0';
  signal in_valid : std_logic := '0';
  signal in_row : std_logic_vector(SLAB_INPUTS_W - 1 downto 0) := (others => '0');
  signal out_valid : std_logic;
  signal out_row : std_logic_vector(SLAB_EXPECTED_W - 1 downto 0);
  signal stg_row : std_logic_vector(SLAB_STAGES_W - 1 downto 0);
  signal done : boolean := false;
  signal in_ready : std_logic;
  signal out_ready : std_logic := '0';
begin
  clk <= not clk after 5 ns when not done;

  fixed : if not HANDSHAKE generate
    dut : entity work.raypipe_slab_ref
      port map (clk => clk, rst_n => rst_n, in_valid => in_valid, in_row => in_row, out_valid => out_valid,
                out_row => out_row, stg_row => stg_row);
    in_ready <= '1';
  end generate;
  stream : if HANDSHAKE generate
    dut : entity work.raypipe_slab_stream
      generic map (DROP => DROP)
      port map (clk => clk, rst_n => rst_n, in_valid => in_valid, in_ready => in_ready, in_row => in_row,
                out_valid => out_valid, out_ready => out_ready, out_row => out_row, stg_row => stg_row);
  end generate;

  main : process
    variable h, rc, pos, k, sent, got, passed, failed, cycle : integer := 0;
    variable cov : integer := -1;
    variable vin : rp_in_t := (others => 0);
    variable vout : rp_out_t;
    variable vstg : rp_stg_t;
    variable outs : out_arr;
    variable stgs : stg_arr;
    variable sent_at : integer_vector(0 to N - 1);
    variable s1 : positive := SEED;
    variable s2 : positive := 7;
    variable r : real;
    variable x : real_vector(0 to 13);
    variable word : std_logic_vector(31 downto 0);
    variable ow, sw : integer_vector(0 to 255);
    variable bits : natural;
    constant timeout : natural := 4 * (LATENCY + 2) + 64;
    variable drawn, waited, lat, lat_max, protocol : natural := 0;
    variable lat_min : natural := natural'high;
    variable hist : integer_vector(0 to 4095) := (others => 0);  -- latencies (the last bin: 4095 or more)
    variable acc, med : natural := 0;
    variable offering, will_take, rdy, held : boolean := false;
    variable held_out : std_logic_vector(SLAB_EXPECTED_W - 1 downto 0);
    variable held_stg : std_logic_vector(SLAB_STAGES_W - 1 downto 0);

    impure function rnd(lo, hi : real) return real is
      variable u : real;
    begin
      uniform(s1, s2, u);
      return lo + (hi - lo) * u;
    end function;

    impure function pick(count : natural) return natural is
    begin
      return integer(floor(rnd(0.0, real(count) - 1.0e-9)));
    end function;

    -- an edge encoding of the format, as a VHDL integer
    impure function edge_value return integer is
      variable b : unsigned(31 downto 0) := (others => '0');
      variable frac : unsigned(31 downto 0);
    begin
      frac := to_unsigned(pick(2 ** minimum(M, 30)), 32);
      if pick(2) = 1 then b(W - 1) := '1'; end if;
      case pick(8) is
        when 0 => null;                                                        -- ±0
        when 1 => b(W - 2 downto M) := (others => '1');                        -- ±inf
        when 2 => b(W - 2 downto M) := (others => '1'); b(M - 1 downto 0) := frac(M - 1 downto 0) or to_unsigned(1, M);  -- NaN
        when 3 => b(M - 1 downto 0) := frac(M - 1 downto 0) or to_unsigned(1, M);  -- subnormal
        when 4 => b(W - 2 downto M + 1) := (others => '1'); b(M - 1 downto 0) := (others => '1');  -- ±max
        when 5 => b(M) := '1';                                                 -- ±min normal
        when 6 => b(0) := '1';                                                 -- least subnormal
        when others => b(M - 1 downto 0) := (others => '1');                   -- largest subnormal
      end case;
      return to_integer(signed(b));
    end function;

    -- draws vector idx: its inputs onto in_row, its expected rows into outs(idx), stgs(idx)
    procedure draw(idx : natural) is
    begin
      -- stimulus: box, origin, aimed or random direction, then edge encodings
      k := pick(100);
      for a in 0 to 2 loop
        r := rnd(0.01, 0.5);
        x(8 + a) := rnd(-1.0, 1.0);
        x(11 + a) := x(8 + a) + 2.0 * r;
        x(a) := rnd(-2.0, 2.0);
        if k < 50 or k >= 70 then
          x(3 + a) := x(8 + a) + r * (1.0 + rnd(-1.0, 1.0)) - x(a);
        else
          x(3 + a) := rnd(-1.0, 1.0);
        end if;
      end loop;
      x(6) := 0.0;
      x(7) := rnd(0.5, 4.0);
      for i in 0 to 13 loop
        vin(i) := rp_vhpi_encode(h, x(i));
      end loop;
      if k >= 70 then
        for j in 0 to pick(3) loop
          vin(pick(14)) := edge_value;
        end loop;
      end if;
      rp_vhpi_eval(h, vin, vout, vstg, rc);
      assert rc = 0 report "rp_vhpi_eval failed (see stderr)" severity failure;
      if cov >= 0 then
        rp_vhpi_cover_add(cov, h, vin, rc);
        assert rc = 0 report "rp_vhpi_cover_add failed (see stderr)" severity failure;
      end if;
      pos := SLAB_EXPECTED_W;
      for i in 0 to rp_vhpi_count(h, 1) - 1 loop
        word := std_logic_vector(to_signed(vout(i), 32));
        outs(idx)(pos - 1 downto pos - ow(i)) := word(ow(i) - 1 downto 0);
        pos := pos - ow(i);
      end loop;
      pos := SLAB_STAGES_W;
      for i in 0 to rp_vhpi_count(h, 2) - 1 loop
        word := std_logic_vector(to_signed(vstg(i), 32));
        stgs(idx)(pos - 1 downto pos - sw(i)) := word(sw(i) - 1 downto 0);
        pos := pos - sw(i);
      end loop;
      pos := SLAB_INPUTS_W - 8;
      in_row(SLAB_INPUTS_W - 1 downto pos) <= (others => '0');
      for i in 0 to 13 loop
        word := std_logic_vector(to_signed(vin(i), 32));
        in_row(pos - 1 downto pos - W) <= word(W - 1 downto 0);
        pos := pos - W;
      end loop;
    end procedure;

    procedure fail(why : string) is
    begin
      failed := failed + 1;
      if failed <= 10 then
        report "FAIL " & why severity note;
      end if;
    end procedure;
  begin
    h := rp_vhpi_new(rp_name("slab"), rp_name(FORMAT), rp_name(OPTIONS));
    assert h >= 0 report "rp_vhpi_new failed (see stderr)" severity failure;
    if COVER_FILE'length > 0 then
      cov := rp_vhpi_cover_new(rp_name("slab"), rp_name(FORMAT), rp_name(OPTIONS));
      assert cov >= 0 report "rp_vhpi_cover_new failed (see stderr)" severity failure;
    end if;
    assert rp_vhpi_count(h, 3) = W and rp_vhpi_count(h, 0) = 14
      report "the live model is not the package's format" severity failure;
    bits := 0;
    for i in 0 to rp_vhpi_count(h, 1) - 1 loop
      ow(i) := rp_vhpi_out_width(h, i);
      bits := bits + ow(i);
    end loop;
    assert bits = SLAB_EXPECTED_W report "the live model's output row is not the package's" severity failure;
    bits := 0;
    for i in 0 to rp_vhpi_count(h, 2) - 1 loop
      sw(i) := rp_vhpi_stage_width(h, i);
      bits := bits + sw(i);
    end loop;
    assert bits = SLAB_STAGES_W report "the live model's stage row is not the package's" severity failure;
    report "raypipe_vhpi_tb: unit slab, format " & FORMAT & ", options """ & OPTIONS & """, " & integer'image(N) &
      " random vectors, seed " & integer'image(SEED) & ", latency " & integer'image(LATENCY) severity note;
    for c in 0 to 2 loop
      wait until falling_edge(clk);
    end loop;
    rst_n <= '1';
    if HANDSHAKE then
      report "raypipe_vhpi_tb: valid/ready, stall " & integer'image(STALL) & " %, timeout " & integer'image(timeout) &
        " ready cycles" severity note;
      loop
        wait until falling_edge(clk);
        cycle := cycle + 1;
        -- the vector offered since the last falling edge went in at the rising edge if in_ready was 1
        if offering and will_take then
          sent_at(sent) := cycle;
          sent := sent + 1;
          offering := false;
        end if;
        -- the output: a held result must not change; out_ready for the next rising edge
        if held and (out_valid /= '1' or out_row /= held_out or stg_row /= held_stg) then
          protocol := protocol + 1;
          fail("protocol at edge " & integer'image(cycle) & ": a result offered without out_ready changed before its transfer");
        end if;
        rdy := STALL = 0 or pick(100) >= STALL;
        if rdy then out_ready <= '1'; else out_ready <= '0'; end if;
        held := false;
        if out_valid = '1' and rdy then
          -- transferred at the next rising edge
          if got >= sent then
            fail("a result with no vector outstanding");
          else
            lat := cycle + 1 - sent_at(got);
            lat_min := minimum(lat_min, lat);
            hist(minimum(lat, hist'high)) := hist(minimum(lat, hist'high)) + 1;
            lat_max := maximum(lat_max, lat);
            if first_diff_slab_expected_t(out_row, outs(got)) /= "none" or first_diff_slab_stages_t(stg_row, stgs(got)) /= "none" then
              fail("vector " & integer'image(got) & ": first output to differ: " & first_diff_slab_expected_t(out_row, outs(got)) &
                   "; first stage signal to differ: " & first_diff_slab_stages_t(stg_row, stgs(got)));
            else
              passed := passed + 1;
            end if;
            got := got + 1;
          end if;
          waited := 0;
        elsif rst_n = '1' then
          held := out_valid = '1';
          held_out := out_row;
          held_stg := stg_row;
          if got < sent and rdy then
            waited := waited + 1;
            if waited > timeout then
              fail("vector " & integer'image(got) & " never came out: no result for " & integer'image(timeout) & " ready cycles");
              exit;
            end if;
          end if;
        end if;
        exit when got = N;
        if not offering and drawn < N then
          draw(drawn);
          in_valid <= '1';
          offering := true;
          drawn := drawn + 1;
        elsif not offering then
          in_valid <= '0';
        end if;
        -- in_ready now holds until the next rising edge (it does not depend on in_valid)
        will_take := in_ready = '1';
      end loop;
      if got > 0 then
        acc := 0;
        for b in hist'range loop
          acc := acc + hist(b);
          if 2 * acc > got then
            med := b;
            exit;
          end if;
        end loop;
        report "latency (edges from input to output transfer): min " & integer'image(lat_min) & ", median " &
          integer'image(med) & ", max " & integer'image(lat_max) & " over " & integer'image(got) & " results" severity note;
      end if;
    else
      loop
        wait until falling_edge(clk);
        cycle := cycle + 1;
        -- score what the last rising edge produced
        if rst_n = '1' and out_valid = '1' then
          if got >= sent then
            fail("out_valid where no vector is due");
          elsif sent_at(got) + LATENCY /= cycle then
            fail("vector " & integer'image(got) & " came " & integer'image(cycle - sent_at(got)) & " edges after its capture");
            got := got + 1;
          else
            if first_diff_slab_expected_t(out_row, outs(got)) /= "none" or first_diff_slab_stages_t(stg_row, stgs(got)) /= "none" then
              fail("vector " & integer'image(got) & ": first output to differ: " & first_diff_slab_expected_t(out_row, outs(got)) &
                   "; first stage signal to differ: " & first_diff_slab_stages_t(stg_row, stgs(got)));
            else
              passed := passed + 1;
            end if;
            got := got + 1;
          end if;
        end if;
        exit when sent = N and cycle > sent_at(N - 1) + LATENCY + 4;
        if sent < N then
          draw(sent);
          in_valid <= '1';
          sent_at(sent) := cycle + 1;
          sent := sent + 1;
        else
          in_valid <= '0';
        end if;
      end loop;
    end if;
    if got < N then
      fail(integer'image(N - got) & " vectors never came out");
    end if;
    report integer'image(passed) & " passed, " & integer'image(failed) & " failed" severity note;
    if cov >= 0 then
      rc := rp_vhpi_cover_write(cov, rp_path(COVER_FILE));
      assert rc >= 0 report "rp_vhpi_cover_write failed (see stderr)" severity failure;
      report "coverage: " & integer'image(rc) & " driven rows recorded in " & COVER_FILE & " (raypipe cover " & COVER_FILE & ")"
        severity note;
    end if;
    done <= true;
    assert failed = 0 report "raypipe_vhpi_tb: " & integer'image(failed) & " vectors failed" severity failure;
    wait;
  end process;
end architecture;
