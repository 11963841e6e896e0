-- raypipe HDL kit (VHDL-2008): the slab reference DUT (slab_ref.vhd) as a valid/ready unit, the
-- VHDL twin of hdl/sv/raypipe_stream.sv's raypipe_stream_of: the core's results go into a FIFO
-- of DEPTH rows; the unit takes an input (in_ready = '1') only while the rows in the core plus
-- the rows in the FIFO are fewer than DEPTH, so no result is ever lost however long out_ready
-- stays low; results leave in input order, offered (out_valid) while the FIFO is not empty, at a
-- rising edge with out_ready = '1'. With DEPTH >= the core's latency + 1 and out_ready always
-- '1' it takes one input per clock. Generic DROP = true is a protocol bug for negative checks:
-- the FIFO drops its head at an edge where out_valid is '1' and out_ready '0'.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.raypipe_slab_pkg.all;

entity raypipe_slab_stream is
  generic (
    DEPTH : positive := 64;
    DROP  : boolean := false
  );
  port (
    clk       : in  std_logic;
    rst_n     : in  std_logic;
    in_valid  : in  std_logic;
    in_ready  : out std_logic;
    in_row    : in  std_logic_vector(SLAB_INPUTS_W - 1 downto 0);
    out_valid : out std_logic;
    out_ready : in  std_logic;
    out_row   : out std_logic_vector(SLAB_EXPECTED_W - 1 downto 0);
    stg_row   : out std_logic_vector(SLAB_STAGES_W - 1 downto 0)
  );
end entity;

architecture rtl of raypipe_slab_stream is
  constant PW : natural := SLAB_EXPECTED_W + SLAB_STAGES_W;
  type mem_t is array (0 to DEPTH - 1) of std_logic_vector(PW - 1 downto 0);
  signal mem : mem_t;
  signal rp, wp : natural range 0 to DEPTH - 1 := 0;
  signal count, inflight : natural range 0 to DEPTH := 0;
  signal take, core_valid, ready_i, valid_i, pop : std_logic;
  function to_sl(b : boolean) return std_logic is
  begin
    if b then return '1'; else return '0'; end if;
  end function;
  constant DROP_BIT : std_logic := to_sl(DROP);
  signal core_out : std_logic_vector(SLAB_EXPECTED_W - 1 downto 0);
  signal core_stg : std_logic_vector(SLAB_STAGES_W - 1 downto 0);
begin
  core : entity work.raypipe_slab_ref
    port map (clk => clk, rst_n => rst_n, in_valid => take, in_row => in_row, out_valid => core_valid,
              out_row => core_out, stg_row => core_stg);
  ready_i <= '1' when rst_n = '1' and inflight + count < DEPTH else '0';
  in_ready <= ready_i;
  take <= in_valid and ready_i;
  valid_i <= '1' when count /= 0 else '0';
  out_valid <= valid_i;
  pop <= valid_i and (out_ready or DROP_BIT);
  out_row <= mem(rp)(PW - 1 downto SLAB_STAGES_W);
  stg_row <= mem(rp)(SLAB_STAGES_W - 1 downto 0);
  process (clk)
    variable c, f : integer;
  begin
    if rising_edge(clk) then
      if rst_n = '0' then
        rp <= 0;
        wp <= 0;
        count <= 0;
        inflight <= 0;
      else
        c := count;
        f := inflight;
        if core_valid = '1' then
          mem(wp) <= core_out & core_stg;
          wp <= (wp + 1) mod DEPTH;
          c := c + 1;
          f := f - 1;
        end if;
        if pop = '1' then
          rp <= (rp + 1) mod DEPTH;
          c := c - 1;
        end if;
        if take = '1' then
          f := f + 1;
        end if;
        count <= c;
        inflight <= f;
      end if;
    end if;
  end process;
end architecture;
