// raypipe behavioural floating point for the reference DUTs of the HDL kit.
//
// One package of functions over IEEE-754-like encodings with E exponent and M fraction bits
// (values right-aligned in 64-bit words), reproducing raypipe's `Ieee` contract bit for bit:
//   * + - x / rounded once to nearest, ties to even; no fused multiply-add;
//   * FTZ (optional): a subnormal operand reads as zero of its sign, a subnormal result
//     (after rounding) becomes zero of its sign;
//   * NaN: canonical (exponent all ones, top fraction bit, sign 0) or propagate (first NaN
//     operand, quieted; invalid operations give the canonical NaN);
//   * compares: IEEE ordered (NaN false, -0 == +0), after the FTZ operand read.
// Specials (NaN, inf, zero operands) are decided in integer logic. Finite operations are
// computed in `real` (binary64) and the binary64 result is rounded to the target in integer
// logic. The product of two finite operands with M <= 24 is exact in binary64; for + and /
// the double rounding is innocuous because 53 >= 2(M+1)+2 (Figueroa). Supported: E <= 9,
// M <= 24 (binary32, binary16, bfloat16 and eEmM customs within that); products and
// quotients of such values stay normal and finite in binary64.
// Works in Icarus Verilog 11 (-g2012), Verilator 5.006 and commercial simulators.
// The larger functions carry /*verilator no_inline_task*/: Verilator inlines every call
// otherwise, and the reference DUTs' ~100 call sites became 70 MB of C++ (a 47 s build; 5 s
// with the functions kept as functions). Other tools read it as a comment.
package raypipe_fp;

  // A format: exponent and fraction widths, flush-to-zero, NaN propagation.
  typedef struct packed {
    logic [7:0] e;
    logic [7:0] m;
    logic       ftz;
    logic       prop;
  } fmt_t;

  typedef logic [63:0] word_t;

  function automatic word_t sign_mask(fmt_t f);
    return word_t'(1) << (f.e + f.m);
  endfunction

  function automatic word_t exp_field(fmt_t f, word_t a);
    return (a >> f.m) & ((word_t'(1) << f.e) - 1);
  endfunction

  function automatic word_t frac_field(fmt_t f, word_t a);
    return a & ((word_t'(1) << f.m) - 1);
  endfunction

  function automatic word_t exp_all_ones(fmt_t f);
    return (word_t'(1) << f.e) - 1;
  endfunction

  function automatic logic is_nan(fmt_t f, word_t a);
    return exp_field(f, a) == exp_all_ones(f) && frac_field(f, a) != 0;
  endfunction

  function automatic logic is_inf(fmt_t f, word_t a);
    return exp_field(f, a) == exp_all_ones(f) && frac_field(f, a) == 0;
  endfunction

  function automatic logic is_zero(fmt_t f, word_t a);
    return (a & ~sign_mask(f)) == 0;
  endfunction

  function automatic logic is_sub(fmt_t f, word_t a);
    return exp_field(f, a) == 0 && frac_field(f, a) != 0;
  endfunction

  function automatic logic sign_of(fmt_t f, word_t a);
    return (a & sign_mask(f)) != 0;
  endfunction

  function automatic word_t canonical_nan(fmt_t f);
    return (exp_all_ones(f) << f.m) | (word_t'(1) << (f.m - 1));
  endfunction

  function automatic word_t inf_of(fmt_t f, logic s);
    return (s ? sign_mask(f) : 0) | (exp_all_ones(f) << f.m);
  endfunction

  function automatic word_t zero_of(fmt_t f, logic s);
    return s ? sign_mask(f) : 0;
  endfunction

  function automatic word_t one_of(fmt_t f);
    return ((word_t'(1) << (f.e - 1)) - 1) << f.m;
  endfunction

  // Operand read: under FTZ a subnormal reads as zero of its sign.
  function automatic word_t rd(fmt_t f, word_t a);
    if (f.ftz && is_sub(f, a)) return a & sign_mask(f);
    return a;
  endfunction

  // The NaN result of an operation on raw operands a, b.
  function automatic word_t nan_result(fmt_t f, word_t a, word_t b);
    if (f.prop && is_nan(f, a)) return a | (word_t'(1) << (f.m - 1));
    if (f.prop && is_nan(f, b)) return b | (word_t'(1) << (f.m - 1));
    return canonical_nan(f);
  endfunction

  // Finite encoding to binary64 (exact).
  function automatic real to_real(fmt_t f, word_t a); /*verilator no_inline_task*/
    word_t e = exp_field(f, a);
    word_t fr = frac_field(f, a);
    word_t out = sign_of(f, a) ? 64'h8000_0000_0000_0000 : 64'h0;
    int bias = (1 << (f.e - 1)) - 1;
    int p;
    int e64;
    if (e == 0 && fr == 0) return $bitstoreal(out);
    if (e == 0) begin
      p = 0;  // position of the leading one of the fraction
      for (int i = 0; i < 64; i++) if (i < f.m && fr[i]) p = i;
      e64 = p + 1 - bias - f.m + 1023;
      out |= word_t'(e64) << 52;
      out |= (fr << (52 - p)) & 64'h000F_FFFF_FFFF_FFFF;
    end else begin
      e64 = int'(e) - bias + 1023;
      out |= word_t'(e64) << 52;
      out |= fr << (52 - f.m);
    end
    return $bitstoreal(out);
  endfunction

  // A finite binary64 value rounded to the format: nearest, ties to even; overflow to
  // infinity; gradual underflow, then the FTZ result flush.
  function automatic word_t from_real(fmt_t f, real r); /*verilator no_inline_task*/
    word_t b = $realtobits(r);
    logic s = b[63];
    int e64 = int'(b[62:52]);
    word_t sig = {11'b0, 1'b1, b[51:0]};  // 53 significant bits
    int bias = (1 << (f.e - 1)) - 1;
    int te = e64 - 1023 + bias;  // target biased exponent if normal
    int sh = 52 - f.m;
    word_t kept, rem, half, out;
    if (b[62:0] == 0) return zero_of(f, s);
    if (te < 1) sh = sh + (1 - te);
    if (sh > 54) begin
      kept = 0;  // below half the smallest subnormal: rounds to zero
    end else begin
      kept = sig >> sh;
      rem = sig & ((word_t'(1) << sh) - 1);
      half = word_t'(1) << (sh - 1);
      if (rem > half || (rem == half && kept[0])) kept = kept + 1;
    end
    if (te < 1) begin
      out = kept;  // a carry into bit m makes the smallest normal, as it should
    end else begin
      if (kept == (word_t'(1) << (f.m + 1))) begin
        kept = kept >> 1;
        te = te + 1;
      end
      if (te >= (1 << f.e) - 1) return inf_of(f, s);
      out = (word_t'(te) << f.m) | (kept & ((word_t'(1) << f.m) - 1));
    end
    if (f.ftz && exp_field(f, out) == 0) out = 0;
    return out | zero_of(f, s);
  endfunction

  // a + b, or a - b when neg is set.
  function automatic word_t addsub(fmt_t f, word_t a, word_t b, logic neg); /*verilator no_inline_task*/
    word_t x = rd(f, a);
    word_t y = rd(f, b);
    if (is_nan(f, x) || is_nan(f, y)) return nan_result(f, a, b);
    if (neg) y = y ^ sign_mask(f);
    if (is_inf(f, x) && is_inf(f, y) && sign_of(f, x) != sign_of(f, y)) return nan_result(f, a, b);
    if (is_inf(f, x)) return x;
    if (is_inf(f, y)) return y;
    return from_real(f, to_real(f, x) + to_real(f, y));
  endfunction

  function automatic word_t fadd(fmt_t f, word_t a, word_t b);
    return addsub(f, a, b, 1'b0);
  endfunction

  function automatic word_t fsub(fmt_t f, word_t a, word_t b);
    return addsub(f, a, b, 1'b1);
  endfunction

  function automatic word_t fmul(fmt_t f, word_t a, word_t b); /*verilator no_inline_task*/
    word_t x = rd(f, a);
    word_t y = rd(f, b);
    logic s = sign_of(f, x) ^ sign_of(f, y);
    if (is_nan(f, x) || is_nan(f, y)) return nan_result(f, a, b);
    if ((is_inf(f, x) && is_zero(f, y)) || (is_zero(f, x) && is_inf(f, y))) return nan_result(f, a, b);
    if (is_inf(f, x) || is_inf(f, y)) return inf_of(f, s);
    if (is_zero(f, x) || is_zero(f, y)) return zero_of(f, s);
    return from_real(f, to_real(f, x) * to_real(f, y));
  endfunction

  // A deliberately wrong multiplier for the kit's negative check: rounds toward zero where
  // a x b rounded to nearest went away from zero (wrong in about half the inexact products).
  function automatic word_t fmul_faulty(fmt_t f, word_t a, word_t b); /*verilator no_inline_task*/
    word_t r = fmul(f, a, b);
    real exact, got;
    if (is_nan(f, r) || is_inf(f, r) || is_zero(f, r) || is_inf(f, a) || is_inf(f, b)) return r;
    exact = to_real(f, rd(f, a)) * to_real(f, rd(f, b));
    got = to_real(f, r);
    if ((got > 0.0 && got > exact) || (got < 0.0 && got < exact)) r = r - 1;
    return r;
  endfunction

  // a / b correctly rounded.
  function automatic word_t fdiv(fmt_t f, word_t a, word_t b); /*verilator no_inline_task*/
    word_t x = rd(f, a);
    word_t y = rd(f, b);
    logic s = sign_of(f, x) ^ sign_of(f, y);
    if (is_nan(f, x) || is_nan(f, y)) return nan_result(f, a, b);
    if ((is_inf(f, x) && is_inf(f, y)) || (is_zero(f, x) && is_zero(f, y))) return nan_result(f, a, b);
    if (is_inf(f, x) || is_zero(f, y)) return inf_of(f, s);
    if (is_zero(f, x) || is_inf(f, y)) return zero_of(f, s);
    return from_real(f, to_real(f, x) / to_real(f, y));
  endfunction

  // The datapath's division: a / b, or a x (1 / b) in recip-mul mode.
  function automatic word_t fdivide(fmt_t f, logic recip_mul, word_t a, word_t b);
    if (recip_mul) return fmul(f, a, fdiv(f, one_of(f), b));
    return fdiv(f, a, b);
  endfunction

  function automatic logic flt(fmt_t f, word_t a, word_t b); /*verilator no_inline_task*/
    word_t x = rd(f, a);
    word_t y = rd(f, b);
    word_t mx = x & ~sign_mask(f);
    word_t my = y & ~sign_mask(f);
    if (is_nan(f, x) || is_nan(f, y)) return 1'b0;
    if (is_zero(f, x) && is_zero(f, y)) return 1'b0;
    if (sign_of(f, x) != sign_of(f, y)) return sign_of(f, x);
    if (sign_of(f, x)) return mx > my;
    return mx < my;
  endfunction

  function automatic logic fle(fmt_t f, word_t a, word_t b); /*verilator no_inline_task*/
    word_t x = rd(f, a);
    word_t y = rd(f, b);
    if (is_nan(f, x) || is_nan(f, y)) return 1'b0;
    if (is_zero(f, x) && is_zero(f, y)) return 1'b1;
    return x == y || flt(f, a, b);
  endfunction

  // |a|: clears the sign bit (NaN payloads kept).
  function automatic word_t fabs(fmt_t f, word_t a);
    return a & ~sign_mask(f);
  endfunction

  // The next encoding above a (NaN and +inf unchanged); under FTZ it skips the subnormals.
  function automatic word_t next_up(fmt_t f, word_t a); /*verilator no_inline_task*/
    word_t r;
    if (is_nan(f, a) || a == inf_of(f, 1'b0)) return a;
    if (is_zero(f, a)) r = f.ftz ? (word_t'(1) << f.m) : 1;
    else if (sign_of(f, a)) r = a - 1;
    else r = a + 1;
    if (f.ftz && is_sub(f, r)) return sign_mask(f);
    return r;
  endfunction

  // The next encoding below a: next_up mirrored through the sign.
  function automatic word_t next_down(fmt_t f, word_t a); /*verilator no_inline_task*/
    if (is_nan(f, a)) return a;
    return next_up(f, a ^ sign_mask(f)) ^ sign_mask(f);
  endfunction

endpackage
