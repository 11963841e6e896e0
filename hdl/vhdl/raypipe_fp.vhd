-- raypipe behavioural floating point for the VHDL-2008 reference DUT of the HDL kit.
--
-- The same contract as hdl/sv/raypipe_fp.sv (raypipe's `Ieee` formats, bit for bit): + - x /
-- rounded once to nearest, ties to even, no fused multiply-add; optional FTZ (subnormal
-- operands read as zero of their sign, subnormal results flushed after rounding); NaN results
-- canonical or the first NaN operand quieted; IEEE ordered compares after the operand read.
-- Specials are decided on the encodings. Finite operations run in `real` (binary64); the
-- binary64 result is rounded to the format by exact scaling by powers of two, so no real-to-bits
-- primitive is needed. Supported: E <= 9, M <= 24 (binary32, binary16, bfloat16, ...).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use ieee.math_real.all;

package raypipe_fp is
  -- an encoding, right-aligned
  subtype word_t is unsigned(63 downto 0);
  -- a format: exponent and fraction widths, flush-to-zero, NaN propagation
  type fmt_t is record
    e    : natural;
    m    : natural;
    ftz  : boolean;
    prop : boolean;
  end record;

  function make_fmt(e, m, ftz, prop : std_logic_vector(63 downto 0)) return fmt_t;
  function w64(x : std_logic_vector) return word_t;
  function is_nan(f : fmt_t; a : word_t) return boolean;
  function is_inf(f : fmt_t; a : word_t) return boolean;
  function is_zero(f : fmt_t; a : word_t) return boolean;
  function is_sub(f : fmt_t; a : word_t) return boolean;
  function sign_of(f : fmt_t; a : word_t) return boolean;
  function canonical_nan(f : fmt_t) return word_t;
  function nan_result(f : fmt_t; a, b : word_t) return word_t;
  function zero_of(f : fmt_t; s : boolean) return word_t;
  function one_of(f : fmt_t) return word_t;
  function rd(f : fmt_t; a : word_t) return word_t;
  function fabs(f : fmt_t; a : word_t) return word_t;
  function fadd(f : fmt_t; a, b : word_t) return word_t;
  function fsub(f : fmt_t; a, b : word_t) return word_t;
  function fmul(f : fmt_t; a, b : word_t) return word_t;
  function fdiv(f : fmt_t; a, b : word_t) return word_t;
  function fdivide(f : fmt_t; recip_mul : boolean; a, b : word_t) return word_t;
  function flt(f : fmt_t; a, b : word_t) return boolean;
  function fle(f : fmt_t; a, b : word_t) return boolean;
  function next_up(f : fmt_t; a : word_t) return word_t;
  function next_down(f : fmt_t; a : word_t) return word_t;
end package raypipe_fp;

package body raypipe_fp is
  function make_fmt(e, m, ftz, prop : std_logic_vector(63 downto 0)) return fmt_t is
  begin
    return (e => to_integer(unsigned(e(7 downto 0))), m => to_integer(unsigned(m(7 downto 0))),
            ftz => ftz(0) = '1', prop => prop(0) = '1');
  end function;

  function w64(x : std_logic_vector) return word_t is
  begin
    return resize(unsigned(x), 64);
  end function;

  function bit_at(k : natural) return word_t is
  begin
    return shift_left(to_unsigned(1, 64), k);
  end function;

  function sign_mask(f : fmt_t) return word_t is
  begin
    return bit_at(f.e + f.m);
  end function;

  function exp_field(f : fmt_t; a : word_t) return natural is
  begin
    return to_integer(shift_right(a, f.m) and (bit_at(f.e) - 1));
  end function;

  function frac_field(f : fmt_t; a : word_t) return natural is
  begin
    return to_integer(a and (bit_at(f.m) - 1));
  end function;

  function all_ones(f : fmt_t) return natural is
  begin
    return 2 ** f.e - 1;
  end function;

  function bias(f : fmt_t) return integer is
  begin
    return 2 ** (f.e - 1) - 1;
  end function;

  function is_nan(f : fmt_t; a : word_t) return boolean is
  begin
    return exp_field(f, a) = all_ones(f) and frac_field(f, a) /= 0;
  end function;

  function is_inf(f : fmt_t; a : word_t) return boolean is
  begin
    return exp_field(f, a) = all_ones(f) and frac_field(f, a) = 0;
  end function;

  function is_zero(f : fmt_t; a : word_t) return boolean is
  begin
    return (a and not sign_mask(f)) = 0;
  end function;

  function is_sub(f : fmt_t; a : word_t) return boolean is
  begin
    return exp_field(f, a) = 0 and frac_field(f, a) /= 0;
  end function;

  function sign_of(f : fmt_t; a : word_t) return boolean is
  begin
    return (a and sign_mask(f)) /= 0;
  end function;

  function canonical_nan(f : fmt_t) return word_t is
  begin
    return shift_left(to_unsigned(all_ones(f), 64), f.m) or bit_at(f.m - 1);
  end function;

  function zero_of(f : fmt_t; s : boolean) return word_t is
  begin
    if s then
      return sign_mask(f);
    end if;
    return (others => '0');
  end function;

  function inf_of(f : fmt_t; s : boolean) return word_t is
  begin
    return zero_of(f, s) or shift_left(to_unsigned(all_ones(f), 64), f.m);
  end function;

  function one_of(f : fmt_t) return word_t is
  begin
    return shift_left(to_unsigned(bias(f), 64), f.m);
  end function;

  function rd(f : fmt_t; a : word_t) return word_t is
  begin
    if f.ftz and is_sub(f, a) then
      return a and sign_mask(f);
    end if;
    return a;
  end function;

  function fabs(f : fmt_t; a : word_t) return word_t is
  begin
    return a and not sign_mask(f);
  end function;

  function nan_result(f : fmt_t; a, b : word_t) return word_t is
  begin
    if f.prop and is_nan(f, a) then
      return a or bit_at(f.m - 1);
    elsif f.prop and is_nan(f, b) then
      return b or bit_at(f.m - 1);
    end if;
    return canonical_nan(f);
  end function;

  -- 2^k, exactly
  function pow2(k : integer) return real is
    variable r : real := 1.0;
  begin
    if k >= 0 then
      for i in 1 to k loop
        r := r * 2.0;
      end loop;
    else
      for i in 1 to -k loop
        r := r * 0.5;
      end loop;
    end if;
    return r;
  end function;

  -- a finite encoding as binary64 (exact)
  function to_real(f : fmt_t; a : word_t) return real is
    variable e : natural := exp_field(f, a);
    variable sig : natural := frac_field(f, a);
    variable k : integer;
    variable r : real;
  begin
    if e = 0 then
      k := 1 - bias(f) - f.m;
    else
      sig := sig + 2 ** f.m;
      k := e - bias(f) - f.m;
    end if;
    r := real(sig) * pow2(k);
    if sign_of(f, a) then
      return -r;
    end if;
    return r;
  end function;

  -- a non-zero finite binary64 value rounded to the format: nearest, ties to even; overflow
  -- to infinity; gradual underflow, then the FTZ result flush
  function from_real(f : fmt_t; r : real) return word_t is
    variable s : boolean := r < 0.0;
    variable a : real := abs(r);
    variable e : integer := 0;
    variable emin : integer := 1 - bias(f);
    variable q : integer;
    variable y, fl, fr : real;
    variable n : natural;
    variable out_w : word_t;
  begin
    while a >= 2.0 loop
      a := a * 0.5;
      e := e + 1;
    end loop;
    while a < 1.0 loop
      a := a * 2.0;
      e := e - 1;
    end loop;
    -- |r| = a * 2^e with 1 <= a < 2; q: the exponent of the format's step at |r|
    if e < emin then
      q := emin - f.m;
    else
      q := e - f.m;
    end if;
    y := a * pow2(e - q);  -- |r| / 2^q, below 2^(m+1): exact
    fl := floor(y);
    fr := y - fl;
    n := natural(fl);
    if fr > 0.5 or (fr = 0.5 and n mod 2 = 1) then
      n := n + 1;
    end if;
    if e < emin then
      out_w := to_unsigned(n, 64);  -- a carry into bit m makes the smallest normal
    else
      if n = 2 ** (f.m + 1) then
        n := n / 2;
        e := e + 1;
      end if;
      if e + bias(f) >= all_ones(f) then
        return inf_of(f, s);
      end if;
      out_w := shift_left(to_unsigned(e + bias(f), 64), f.m) or to_unsigned(n - 2 ** f.m, 64);
    end if;
    if f.ftz and exp_field(f, out_w) = 0 then
      out_w := (others => '0');
    end if;
    return out_w or zero_of(f, s);
  end function;

  function addsub(f : fmt_t; a, b : word_t; neg : boolean) return word_t is
    variable x : word_t := rd(f, a);
    variable y : word_t := rd(f, b);
    variable r : real;
  begin
    if is_nan(f, x) or is_nan(f, y) then
      return nan_result(f, a, b);
    end if;
    if neg then
      y := y xor sign_mask(f);
    end if;
    if is_inf(f, x) and is_inf(f, y) and sign_of(f, x) /= sign_of(f, y) then
      return nan_result(f, a, b);
    elsif is_inf(f, x) then
      return x;
    elsif is_inf(f, y) then
      return y;
    elsif is_zero(f, x) and is_zero(f, y) then
      return zero_of(f, sign_of(f, x) and sign_of(f, y));  -- -0 only for -0 + -0
    elsif is_zero(f, y) then
      return x;
    elsif is_zero(f, x) then
      return y;
    end if;
    r := to_real(f, x) + to_real(f, y);
    if r = 0.0 then
      return zero_of(f, false);  -- exact cancellation is +0 when rounding to nearest
    end if;
    return from_real(f, r);
  end function;

  function fadd(f : fmt_t; a, b : word_t) return word_t is
  begin
    return addsub(f, a, b, false);
  end function;

  function fsub(f : fmt_t; a, b : word_t) return word_t is
  begin
    return addsub(f, a, b, true);
  end function;

  function fmul(f : fmt_t; a, b : word_t) return word_t is
    variable x : word_t := rd(f, a);
    variable y : word_t := rd(f, b);
    variable s : boolean := sign_of(f, x) xor sign_of(f, y);
  begin
    if is_nan(f, x) or is_nan(f, y) then
      return nan_result(f, a, b);
    elsif (is_inf(f, x) and is_zero(f, y)) or (is_zero(f, x) and is_inf(f, y)) then
      return nan_result(f, a, b);
    elsif is_inf(f, x) or is_inf(f, y) then
      return inf_of(f, s);
    elsif is_zero(f, x) or is_zero(f, y) then
      return zero_of(f, s);
    end if;
    return from_real(f, to_real(f, x) * to_real(f, y));
  end function;

  function fdiv(f : fmt_t; a, b : word_t) return word_t is
    variable x : word_t := rd(f, a);
    variable y : word_t := rd(f, b);
    variable s : boolean := sign_of(f, x) xor sign_of(f, y);
  begin
    if is_nan(f, x) or is_nan(f, y) then
      return nan_result(f, a, b);
    elsif (is_inf(f, x) and is_inf(f, y)) or (is_zero(f, x) and is_zero(f, y)) then
      return nan_result(f, a, b);
    elsif is_inf(f, x) or is_zero(f, y) then
      return inf_of(f, s);
    elsif is_zero(f, x) or is_inf(f, y) then
      return zero_of(f, s);
    end if;
    return from_real(f, to_real(f, x) / to_real(f, y));
  end function;

  function fdivide(f : fmt_t; recip_mul : boolean; a, b : word_t) return word_t is
  begin
    if recip_mul then
      return fmul(f, a, fdiv(f, one_of(f), b));
    end if;
    return fdiv(f, a, b);
  end function;

  function flt(f : fmt_t; a, b : word_t) return boolean is
    variable x : word_t := rd(f, a);
    variable y : word_t := rd(f, b);
  begin
    if is_nan(f, x) or is_nan(f, y) or (is_zero(f, x) and is_zero(f, y)) then
      return false;
    elsif sign_of(f, x) /= sign_of(f, y) then
      return sign_of(f, x);
    elsif sign_of(f, x) then
      return fabs(f, x) > fabs(f, y);
    end if;
    return fabs(f, x) < fabs(f, y);
  end function;

  function fle(f : fmt_t; a, b : word_t) return boolean is
    variable x : word_t := rd(f, a);
    variable y : word_t := rd(f, b);
  begin
    if is_nan(f, x) or is_nan(f, y) then
      return false;
    elsif is_zero(f, x) and is_zero(f, y) then
      return true;
    end if;
    return x = y or flt(f, a, b);
  end function;

  function next_up(f : fmt_t; a : word_t) return word_t is
    variable r : word_t;
  begin
    if is_nan(f, a) or a = inf_of(f, false) then
      return a;
    elsif is_zero(f, a) then
      if f.ftz then
        r := bit_at(f.m);
      else
        r := to_unsigned(1, 64);
      end if;
    elsif sign_of(f, a) then
      r := a - 1;
    else
      r := a + 1;
    end if;
    if f.ftz and is_sub(f, r) then
      return sign_mask(f);
    end if;
    return r;
  end function;

  function next_down(f : fmt_t; a : word_t) return word_t is
  begin
    if is_nan(f, a) then
      return a;
    end if;
    return next_up(f, a xor sign_mask(f)) xor sign_mask(f);
  end function;
end package body raypipe_fp;
