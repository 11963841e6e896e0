-- Reference DUT of the `slab` ray-box unit in VHDL-2008 (raypipe HDL kit): the stage
-- pipeline of hdl/sv/ref/slab_ref.sv, one register per stage of raypipe's slab stage table,
-- latency 7. Rows are packed as the lines of slab_inputs.hex / slab_expected.hex /
-- slab_stages.hex (see the generated raypipe_slab_pkg).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.raypipe_fp.all;
use work.raypipe_slab_pkg.all;

entity raypipe_slab_ref is
  port (
    clk       : in  std_logic;
    rst_n     : in  std_logic;
    in_valid  : in  std_logic;
    in_row    : in  std_logic_vector(SLAB_INPUTS_W - 1 downto 0);
    out_valid : out std_logic;
    out_row   : out std_logic_vector(SLAB_EXPECTED_W - 1 downto 0);
    stg_row   : out std_logic_vector(SLAB_STAGES_W - 1 downto 0)
  );
end entity;

architecture behavioural of raypipe_slab_ref is
  constant F : fmt_t := make_fmt(P_EXP, P_MAN, P_FTZ, P_NAN_PROPAGATE);
  constant W : natural := to_integer(unsigned(P_WIDTH(7 downto 0)));
  constant RECIP_MUL : boolean := P_RECIP_MUL(0) = '1';
  constant DELTA : word_t := unsigned(P_SLAB_DELTA);
  constant L : natural := LATENCY;

  type state_t is record
    i : slab_inputs_t;
    s : slab_stages_t;
  end record;
  type pipe_t is array (0 to L) of state_t;
  signal st : pipe_t;
  signal v : std_logic_vector(0 to L) := (others => '0');

  function nw(x : word_t) return std_logic_vector is
  begin
    return std_logic_vector(x(W - 1 downto 0));
  end function;

  function flag(b : boolean) return std_logic_vector is
  begin
    if b then
      return "1";
    end if;
    return "0";
  end function;

  -- the ray's input read: a NaN reads as the canonical NaN (quieted, payload kept, under
  -- propagate), under FTZ a subnormal as zero of its sign
  function conv(a : std_logic_vector) return std_logic_vector is
  begin
    if is_nan(F, w64(a)) then
      return nw(nan_result(F, w64(a), w64(a)));
    end if;
    return nw(rd(F, w64(a)));
  end function;

  function prep(d : std_logic_vector) return std_logic_vector is
  begin
    if P_SLAB_EMBREE(0) = '0' or not flt(F, fabs(F, w64(d)), DELTA) then
      return d;
    elsif sign_of(F, w64(d)) then
      return nw(fsub(F, zero_of(F, false), DELTA));
    end if;
    return nw(DELTA);
  end function;

  function near_sel(acc, x : std_logic_vector) return std_logic_vector is
  begin
    if P_SLAB_TAKE_ON_FALSE(0) = '1' then
      if fle(F, w64(x), w64(acc)) then return acc; end if;
      return x;
    end if;
    if flt(F, w64(acc), w64(x)) then return x; end if;
    return acc;
  end function;

  function far_sel(acc, x : std_logic_vector) return std_logic_vector is
  begin
    if P_SLAB_TAKE_ON_FALSE(0) = '1' then
      if fle(F, w64(acc), w64(x)) then return acc; end if;
      return x;
    end if;
    if flt(F, w64(x), w64(acc)) then return x; end if;
    return acc;
  end function;

  -- a number that is neither NaN nor infinite
  function finite(a : word_t) return boolean is
  begin
    return not is_nan(F, a) and not is_inf(F, a);
  end function;

  -- a stage-1 subtract; the conservative variant's guard (P_SLAB_GUARD): finite operands
  -- whose difference overflowed to +-inf give the canonical NaN
  function sub(a, b : std_logic_vector) return std_logic_vector is
    variable r : word_t := fsub(F, w64(a), w64(b));
  begin
    if P_SLAB_GUARD(0) = '1' and finite(w64(a)) and finite(w64(b)) and is_inf(F, r) then
      return nw(canonical_nan(F));
    end if;
    return nw(r);
  end function;

  function mul(a, b : std_logic_vector) return std_logic_vector is
  begin
    return nw(fmul(F, w64(a), w64(b)));
  end function;

  -- 1 / d; the guard: a finite nonzero d whose reciprocal is not a normal number (+-inf,
  -- +-0 or subnormal) gives the canonical NaN
  function recip(d : std_logic_vector) return std_logic_vector is
    variable r : word_t := fdivide(F, RECIP_MUL, one_of(F), w64(d));
  begin
    if P_SLAB_GUARD(0) = '1' and finite(w64(d)) and not is_zero(F, w64(d))
       and (is_inf(F, r) or is_zero(F, r) or is_sub(F, r)) then
      return nw(canonical_nan(F));
    end if;
    return nw(r);
  end function;

  function sel(c : std_logic_vector; a, b : std_logic_vector) return std_logic_vector is
  begin
    if c = "1" then return a; end if;
    return b;
  end function;

  -- table stage k - 1 applied to the state registered by stage k - 1
  function stage(k : natural; x : state_t) return state_t is
    variable y : state_t := x;
    variable n, f_w : word_t;
  begin
    case k - 1 is
      when 0 =>
        y.s.dx := conv(x.i.dx); y.s.dy := conv(x.i.dy); y.s.dz := conv(x.i.dz);
        y.i.ox := conv(x.i.ox); y.i.oy := conv(x.i.oy); y.i.oz := conv(x.i.oz);
        y.i.tmin := conv(x.i.tmin); y.i.tmax := conv(x.i.tmax);
        y.s.pdx := prep(y.s.dx); y.s.pdy := prep(y.s.dy); y.s.pdz := prep(y.s.dz);
        y.s.inv_dx := recip(y.s.pdx); y.s.inv_dy := recip(y.s.pdy); y.s.inv_dz := recip(y.s.pdz);
      when 1 =>
        y.s.lox := sub(x.i.minx, x.i.ox); y.s.hix := sub(x.i.maxx, x.i.ox);
        y.s.loy := sub(x.i.miny, x.i.oy); y.s.hiy := sub(x.i.maxy, x.i.oy);
        y.s.loz := sub(x.i.minz, x.i.oz); y.s.hiz := sub(x.i.maxz, x.i.oz);
      when 2 =>
        y.s.tlox := mul(x.s.lox, x.s.inv_dx); y.s.thix := mul(x.s.hix, x.s.inv_dx);
        y.s.tloy := mul(x.s.loy, x.s.inv_dy); y.s.thiy := mul(x.s.hiy, x.s.inv_dy);
        y.s.tloz := mul(x.s.loz, x.s.inv_dz); y.s.thiz := mul(x.s.hiz, x.s.inv_dz);
      when 3 =>
        y.s.negx := flag(sign_of(F, w64(x.s.inv_dx)));
        y.s.negy := flag(sign_of(F, w64(x.s.inv_dy)));
        y.s.negz := flag(sign_of(F, w64(x.s.inv_dz)));
        y.s.nearx := sel(y.s.negx, x.s.thix, x.s.tlox); y.s.farx := sel(y.s.negx, x.s.tlox, x.s.thix);
        y.s.neary := sel(y.s.negy, x.s.thiy, x.s.tloy); y.s.fary := sel(y.s.negy, x.s.tloy, x.s.thiy);
        y.s.nearz := sel(y.s.negz, x.s.thiz, x.s.tloz); y.s.farz := sel(y.s.negz, x.s.tloz, x.s.thiz);
      when 4 =>
        y.s.tn_x := near_sel(x.i.tmin, x.s.nearx);
        y.s.tn_xy := near_sel(y.s.tn_x, x.s.neary);
        y.s.tn_xyz := near_sel(y.s.tn_xy, x.s.nearz);
        y.s.tf_x := far_sel(x.i.tmax, x.s.farx);
        y.s.tf_xy := far_sel(y.s.tf_x, x.s.fary);
        y.s.tf_xyz := far_sel(y.s.tf_xy, x.s.farz);
      when 5 =>
        n := w64(x.s.tn_xyz);
        f_w := w64(x.s.tf_xyz);
        for j in 1 to to_integer(unsigned(P_SLAB_WIDEN_ULPS(15 downto 0))) loop
          n := next_down(F, n);
          f_w := next_up(F, f_w);
        end loop;
        y.s.t_near := nw(n);
        y.s.t_far := nw(f_w);
      when others =>
        y.s.hit := flag(fle(F, w64(x.s.t_near), w64(x.s.t_far)));
    end case;
    return y;
  end function;
begin
  process (clk)
  begin
    if rising_edge(clk) then
      v(0) <= rst_n and in_valid;
      if in_valid = '1' then
        st(0).i <= to_slab_inputs_t(in_row);
        st(0).s <= to_slab_stages_t((others => '0'));
      end if;
      for k in 1 to L loop
        v(k) <= rst_n and v(k - 1);
        if v(k - 1) = '1' then  -- idle registers hold (no arithmetic on undefined bits)
          st(k) <= stage(k, st(k - 1));
        end if;
      end loop;
    end if;
  end process;

  out_valid <= v(L);
  out_row <= st(L).s.hit & st(L).s.t_near & st(L).s.t_far;
  stg_row <= from_slab_stages_t(st(L).s);
end architecture;
