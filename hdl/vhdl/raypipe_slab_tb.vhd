-- raypipe HDL kit: the VHDL-2008 testbench of the slab unit (GHDL 2, any VHDL-2008 simulator).
-- Reads slab_inputs.hex, slab_expected.hex and slab_stages.hex of a vector set with hread,
-- drives one vector per clock into raypipe_slab_ref (or an entity with the same ports) with
-- an idle cycle every GAP cycles, expects each result exactly LATENCY rising edges after the
-- edge that captured it, compares every output and stage signal, and reports
-- `N passed, M failed`; a failure ends the run with severity failure (non-zero exit). The valid
-- timing is checked cycle by cycle: an out_valid pulse where no vector is due is an extra pulse
-- at that edge (no vector consumed), a due vector without out_valid a missing pulse for that
-- vector; failure lines name the vector's class.
-- Generics: SET_DIR (the vector set), GAP (default 5; 0 = back to back), STAGES (default true).
-- hdl/run --sim ghdl --dut NAME replaces the entity name raypipe_slab_ref below with NAME.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use std.textio.all;
use work.raypipe_slab_pkg.all;

entity raypipe_slab_tb is
  generic (
    SET_DIR  : string := "set";
    GAP      : natural := 5;
    STAGES   : boolean := true
  );
end entity;

architecture sim of raypipe_slab_tb is
  constant N : natural := N_VECTORS;
  type in_arr is array (0 to N - 1) of std_logic_vector(SLAB_INPUTS_W - 1 downto 0);
  type out_arr is array (0 to N - 1) of std_logic_vector(SLAB_EXPECTED_W - 1 downto 0);
  type stg_arr is array (0 to N - 1) of std_logic_vector(SLAB_STAGES_W - 1 downto 0);

  impure function digits(w : natural) return natural is
  begin
    return (w + 3) / 4;
  end function;

  signal clk : std_logic := '0';
  signal rst_n : std_logic := '0';
  signal in_valid : std_logic := '0';
  signal in_row : std_logic_vector(SLAB_INPUTS_W - 1 downto 0) := (others => '0');
  signal out_valid : std_logic;
  signal out_row : std_logic_vector(SLAB_EXPECTED_W - 1 downto 0);
  signal stg_row : std_logic_vector(SLAB_STAGES_W - 1 downto 0);
  signal done : boolean := false;
  signal cycle : natural := 0;
begin
  clk <= not clk after 5 ns when not done;

  dut : entity work.raypipe_slab_ref
    port map (clk => clk, rst_n => rst_n, in_valid => in_valid, in_row => in_row, out_valid => out_valid,
              out_row => out_row, stg_row => stg_row);

  process (clk)
  begin
    if rising_edge(clk) then
      cycle <= cycle + 1;
    end if;
  end process;

  main : process
    file fi : text;
    variable ln : line;
    variable ins : in_arr;
    variable outs : out_arr;
    variable stgs : stg_arr;
    variable sent_at : integer_vector(0 to N - 1);
    variable sent, got, passed, failed : natural := 0;
    variable due : boolean;

    impure function hex_row(w : natural) return std_logic_vector is
      variable v : std_logic_vector(4 * digits(w) - 1 downto 0);
    begin
      readline(fi, ln);
      hread(ln, v);
      return v(w - 1 downto 0);
    end function;

    procedure report_fail(i : natural; why : string) is
      variable cls : natural;
    begin
      failed := failed + 1;
      if failed = 1 then
        -- hdl/run reads this line to write the failing run's waveform
        report "first failure at simulation time " & integer'image(now / 1 ns) & " ns" severity note;
      end if;
      cls := to_integer(unsigned(ins(i)(SLAB_INPUTS_W - 1 downto SLAB_INPUTS_W - 8)));
      if failed <= 10 then
        report "FAIL vector " & integer'image(i) & " (line " & integer'image(i + 1) & ", class " &
          integer'image(cls) & " " & class_name(cls) & "): " & why severity note;
      end if;
    end procedure;
  begin
    file_open(fi, SET_DIR & "/slab_inputs.hex", read_mode);
    for i in 0 to N - 1 loop ins(i) := hex_row(SLAB_INPUTS_W); end loop;
    file_close(fi);
    file_open(fi, SET_DIR & "/slab_expected.hex", read_mode);
    for i in 0 to N - 1 loop outs(i) := hex_row(SLAB_EXPECTED_W); end loop;
    file_close(fi);
    file_open(fi, SET_DIR & "/slab_stages.hex", read_mode);
    for i in 0 to N - 1 loop stgs(i) := hex_row(SLAB_STAGES_W); end loop;
    file_close(fi);
    report "raypipe_slab_tb: " & integer'image(N) & " vectors from " & SET_DIR & ", latency " &
      integer'image(LATENCY) severity note;
    wait until falling_edge(clk);
    wait until falling_edge(clk);
    rst_n <= '1';
    -- drive at the falling edge, compare at the falling edge what the last rising edge produced
    while got < N loop
      wait until falling_edge(clk);
      due := got < sent and cycle = sent_at(got) + LATENCY;
      if out_valid = '1' and not due then
        failed := failed + 1;
        if failed <= 10 then
          report "FAIL: extra out_valid pulse at edge " & integer'image(cycle) & ": no vector is due" severity note;
        end if;
      elsif due and out_valid /= '1' then
        report_fail(got, "missing out_valid pulse at edge " & integer'image(cycle) & " (" &
                    integer'image(LATENCY) & " edges after the edge that captured it)");
        got := got + 1;
      elsif due then
        if out_row /= outs(got) then
          report_fail(got, "first output to differ: " & first_diff_slab_expected_t(out_row, outs(got)) &
                      "; first stage signal to differ: " & first_diff_slab_stages_t(stg_row, stgs(got)));
        elsif STAGES and stg_row /= stgs(got) then
          report_fail(got, "first stage signal to differ: " & first_diff_slab_stages_t(stg_row, stgs(got)));
        else
          passed := passed + 1;
        end if;
        got := got + 1;
      end if;
      if sent < N and not (GAP > 0 and cycle mod GAP = GAP - 1) then
        in_valid <= '1';
        in_row <= ins(sent);
        sent_at(sent) := cycle + 1;
        sent := sent + 1;
      else
        in_valid <= '0';
      end if;
      if sent = N and cycle > sent_at(N - 1) + LATENCY + 4 and got < N then
        report_fail(got, integer'image(N - got) & " vectors gave no result");
        failed := failed + N - got - 1;
        exit;
      end if;
    end loop;
    report integer'image(passed) & " passed, " & integer'image(failed) & " failed" severity note;
    done <= true;
    assert failed = 0 report "raypipe_slab_tb: " & integer'image(failed) & " of " & integer'image(N) &
      " vectors failed" severity failure;
    wait;
  end process;
end architecture;
