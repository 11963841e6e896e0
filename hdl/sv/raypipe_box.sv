// raypipe HDL kit: the slab unit's ray setup and compare-select rules, shared by the slab and
// traverse reference DUTs. Compile after the set's raypipe_pkg.sv (it reads the format and
// the slab variant from raypipe_set_pkg) and raypipe_fp.sv.
package raypipe_box;
  import raypipe_fp::*;
  import raypipe_set_pkg::*;

  // the set's format, as an fmt_t
  localparam logic [$bits(fmt_t)-1:0] F = {EXP[7:0], MAN[7:0], FTZ[0], NAN_PROPAGATE[0]};

  // The ray's input read: a NaN reads as the canonical NaN (quieted, payload kept, under
  // propagate), under FTZ a subnormal as zero of its sign.
  function automatic word_t conv(word_t a);
    if (is_nan(F, a)) return nan_result(F, a, a);
    return rd(F, a);
  endfunction

  // Embree's preparation: |d| < delta becomes +-delta by the sign bit of d.
  function automatic word_t prep(word_t d);
    if (!SLAB_EMBREE[0] || !flt(F, fabs(F, d), SLAB_DELTA)) return d;
    return sign_of(F, d) ? fsub(F, zero_of(F, 1'b0), SLAB_DELTA) : SLAB_DELTA;
  endfunction

  // the guard's enable; RAYPIPE_NO_GUARD leaves it out (a negative check of hdl/selftest: a
  // conservative unit without the guard must fail the set)
`ifdef RAYPIPE_NO_GUARD
  localparam logic GUARD = 1'b0;
`else
  localparam logic GUARD = SLAB_GUARD[0];
`endif

  // a number that is neither NaN nor infinite
  function automatic logic finite(word_t a);
    return !is_nan(F, a) && !is_inf(F, a);
  endfunction

  // 1 / d in the datapath's division; the conservative variant's guard (SLAB_GUARD): a finite
  // nonzero d whose reciprocal is not a normal number (+-inf, +-0 or subnormal) gives the
  // canonical NaN
  function automatic word_t recip(word_t d);
    word_t r = fdivide(F, RECIP_MUL[0], one_of(F), d);
    if (GUARD && finite(d) && !is_zero(F, d) && (is_inf(F, r) || is_zero(F, r) || is_sub(F, r)))
      return canonical_nan(F);
    return r;
  endfunction

  // a stage-1 subtract; the guard: finite operands whose difference overflowed to +-inf give
  // the canonical NaN
  function automatic word_t gsub(word_t a, word_t b);
    word_t r = fsub(F, a, b);
    if (GUARD && finite(a) && finite(b) && is_inf(F, r)) return canonical_nan(F);
    return r;
  endfunction

  // near chain: acc replaced by x when x is farther in (NaN: plain keeps acc, take-on-false takes x)
  function automatic word_t near_sel(word_t acc, word_t x);
    if (SLAB_TAKE_ON_FALSE[0]) return fle(F, x, acc) ? acc : x;
    return flt(F, acc, x) ? x : acc;
  endfunction

  function automatic word_t far_sel(word_t acc, word_t x);
    if (SLAB_TAKE_ON_FALSE[0]) return fle(F, acc, x) ? acc : x;
    return flt(F, x, acc) ? x : acc;
  endfunction

  // t_near stepped SLAB_WIDEN_ULPS grid steps toward -inf (IEEE nextDown), t_far toward +inf (nextUp)
  function automatic word_t widen(word_t t, logic up);
    for (int j = 0; j < int'(SLAB_WIDEN_ULPS); j++) t = up ? next_up(F, t) : next_down(F, t);
    return t;
  endfunction

  // A ray after setup: converted origin and t interval, and 1/d.
  typedef struct packed {
    word_t ox, oy, oz, ix, iy, iz, tmin, tmax;
  } ray_t;

  function automatic ray_t setup(word_t ox, word_t oy, word_t oz, word_t dx, word_t dy, word_t dz, word_t tmin,
                                 word_t tmax);
    ray_t r;
    r.ox = conv(ox);
    r.oy = conv(oy);
    r.oz = conv(oz);
    r.ix = recip(prep(conv(dx)));
    r.iy = recip(prep(conv(dy)));
    r.iz = recip(prep(conv(dz)));
    r.tmin = conv(tmin);
    r.tmax = conv(tmax);
    return r;
  endfunction

  // One whole box test (stages 1 to 6): {hit, widened t_near}.
  function automatic logic [64:0] test(ray_t r, word_t minx, word_t miny, word_t minz, word_t maxx, word_t maxy,
                                       word_t maxz);
    word_t tlx = fmul(F, gsub(minx, r.ox), r.ix);
    word_t thx = fmul(F, gsub(maxx, r.ox), r.ix);
    word_t tly = fmul(F, gsub(miny, r.oy), r.iy);
    word_t thy = fmul(F, gsub(maxy, r.oy), r.iy);
    word_t tlz = fmul(F, gsub(minz, r.oz), r.iz);
    word_t thz = fmul(F, gsub(maxz, r.oz), r.iz);
    logic nx = sign_of(F, r.ix);
    logic ny = sign_of(F, r.iy);
    logic nz = sign_of(F, r.iz);
    word_t tn = near_sel(near_sel(near_sel(r.tmin, nx ? thx : tlx), ny ? thy : tly), nz ? thz : tlz);
    word_t tf = far_sel(far_sel(far_sel(r.tmax, nx ? tlx : thx), ny ? tly : thy), nz ? tlz : thz);
    tn = widen(tn, 1'b0);
    tf = widen(tf, 1'b1);
    return {fle(F, tn, tf), tn};
  endfunction
endpackage
