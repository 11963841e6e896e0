//! The kernel bodies (`rti_kernel!`, `slab_kernel!`) and their instances per instruction set and
//! format.

#[allow(unused_imports)]
use super::isa;
use super::select::*;

use crate::format::{DivMode, F16Half, F32Native, Ieee, Subnormals};
use crate::rti::{Cull, HitsSoa, RaysSoa, Rti, TrisSoa};
use crate::slab::{BoxesSoa, Slab, SlabNan, SlabOutSoa};
use crate::Format as _;
use half::f16;

/// The RTI stage table on one vector per step, in the ops of `$x` (an [`isa`] module).
/// `$load(column, i)` gives the lanes as binary32, `$round(x)` rounds a binary32 result to
/// the format, `$store(column, i, x)` writes results, `$thr` is the det threshold as binary32.
macro_rules! rti_kernel {
    ($x:ident, $rti:expr, $rays:expr, $tris:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $thr:expr, $start:expr, $end:expr) => {{
        let round = $round;
        rti_kernel!($x, $rti, $rays, $tris, $out, $full, $load, round, round, |b| b, |a, b, _| round($x::mul(a, b)), |_: &[_; 12]| true, $store, $thr, $start, $end)
    }};
    // `$fast` rounds without the filter; `$fmulk(a, b, $k(b))` is `$fast` of the product
    // a·b (`$k(b)` formed once for the products that share b); `$ok(v)` (v: the stage-1
    // results and the direction) says that `$fast` gives `$round`'s results at stages 2-6
    // on every lane
    ($x:ident, $rti:expr, $rays:expr, $tris:expr, $out:expr, $full:expr, $load:expr, $round:expr, $fast:expr, $k:expr, $fmulk:expr, $ok:expr, $store:expr, $thr:expr, $start:expr, $end:expr) => {{
        // one loop per (culling, division mode), so that neither is decided per vector
        let backface = $rti.cull == Cull::Backface;
        match ($rti.fmt.opts.div, backface) {
            (DivMode::RecipMul, false) => rti_kernel!(@loop $x, $rti, $rays, $tris, $out, $full, $load, $round, $fast, $k, $fmulk, $ok, $store, $thr, $start, $end, false, true),
            (DivMode::RecipMul, true) => rti_kernel!(@loop $x, $rti, $rays, $tris, $out, $full, $load, $round, $fast, $k, $fmulk, $ok, $store, $thr, $start, $end, true, true),
            (DivMode::Divide, false) => rti_kernel!(@loop $x, $rti, $rays, $tris, $out, $full, $load, $round, $fast, $k, $fmulk, $ok, $store, $thr, $start, $end, false, false),
            (DivMode::Divide, true) => rti_kernel!(@loop $x, $rti, $rays, $tris, $out, $full, $load, $round, $fast, $k, $fmulk, $ok, $store, $thr, $start, $end, true, false),
        }
    }};
    // stage 1 in `$sub`: (e1, e2, s)
    (@stage1 $sub:ident, $v:ident, $ox:ident, $oy:ident, $oz:ident) => {{
        let (v0x, v0y, v0z) = ($v(0, 0), $v(0, 1), $v(0, 2));
        (
            ($sub($v(1, 0), v0x), $sub($v(1, 1), v0y), $sub($v(1, 2), v0z)),
            ($sub($v(2, 0), v0x), $sub($v(2, 1), v0y), $sub($v(2, 2), v0z)),
            ($sub($ox, v0x), $sub($oy, v0y), $sub($oz, v0z)),
        )
    }};
    // stages 2-6 in `$sub`, `$add`, `$mul`: [det, u', v', t']. The 18 products with a
    // factor of d or s go through `$mulk(a, b, $k(b))` with b that factor (multiplication
    // commutes: `$mulk(e2z, dy, ..)` is the product dy·e2z of the table)
    (@stages26 $sub:ident, $add:ident, $mul:ident, $k:ident, $mulk:ident, $e1:expr, $e2:expr, $s:expr, $d:expr) => {{
        let ((e1x, e1y, e1z), (e2x, e2y, e2z), (sx, sy, sz), (dx, dy, dz)) = ($e1, $e2, $s, $d);
        let (kdx, kdy, kdz) = ($k(dx), $k(dy), $k(dz));
        let (ksx, ksy, ksz) = ($k(sx), $k(sy), $k(sz));
        // stages 2, 3: p = d x e2, q = s x e1
        let px = $sub($mulk(e2z, dy, kdy), $mulk(e2y, dz, kdz));
        let py = $sub($mulk(e2x, dz, kdz), $mulk(e2z, dx, kdx));
        let pz = $sub($mulk(e2y, dx, kdx), $mulk(e2x, dy, kdy));
        let qx = $sub($mulk(e1z, sy, ksy), $mulk(e1y, sz, ksz));
        let qy = $sub($mulk(e1x, sz, ksz), $mulk(e1z, sx, ksx));
        let qz = $sub($mulk(e1y, sx, ksx), $mulk(e1x, sy, ksy));
        // stages 4-6: (x + y) + z
        let det = $add($add($mul(e1x, px), $mul(e1y, py)), $mul(e1z, pz));
        let up = $add($add($mulk(px, sx, ksx), $mulk(py, sy, ksy)), $mulk(pz, sz, ksz));
        let vp = $add($add($mulk(qx, dx, kdx), $mulk(qy, dy, kdy)), $mulk(qz, dz, kdz));
        let tp = $add($add($mul(e2x, qx), $mul(e2y, qy)), $mul(e2z, qz));
        [det, up, vp, tp]
    }};
    (@loop $x:ident, $rti:expr, $rays:expr, $tris:expr, $out:expr, $full:expr, $load:expr, $round:expr, $fast:expr, $k:expr, $fmulk:expr, $ok:expr, $store:expr, $thr:expr, $start:expr, $end:expr, $backface:expr, $recip:expr) => {{
        let (rays, tris, out) = ($rays, $tris, $out);
        let load = $load;
        let rd = $round;
        let fast = $fast;
        let ok = $ok;
        let fsub = |a, b| fast($x::sub(a, b));
        let fadd = |a, b| fast($x::add(a, b));
        let fmul = |a, b| fast($x::mul(a, b));
        let (fk, fmulk) = ($k, $fmulk);
        // the filtered path's products as the table's: no factor formed ahead
        let (nok, mulk) = (|b| b, |a, b, _| rd($x::mul(a, b)));
        let store = $store;
        // called before and after each block of vectors (the narrow formats' filter)
        let (start, end) = ($start, $end);
        let sub = |a, b| rd($x::sub(a, b));
        let add = |a, b| rd($x::add(a, b));
        let mul = |a, b| rd($x::mul(a, b));
        let div = |a, b| rd($x::div(a, b));
        let thr = $x::splat($thr);
        let zero = $x::splat(0.0);
        let one = $x::splat(1.0);
        // the canonical NaN of the lanes' encoding (stored as the format's canonical NaN)
        let nan = $x::canonical_nan();
        const L: usize = $x::LANES;
        // Two passes over blocks of BLOCK vectors (software pipelining): the first runs
        // stages 1-6 and keeps det, u', v' and t'; the second runs stage 7, divides and
        // stores.
        // The divide's latency then overlaps the next block's arithmetic instead of
        // filling the scheduler with instructions that wait for it.
        const BLOCK: usize = 8;
        let mut keep = [[zero; 4]; BLOCK];
        // which vectors of the block took the unfiltered stages 2-6 (and so stage 7's u + v)
        let mut unfiltered = [false; BLOCK];
        // the NaN lanes of each vector of the block (bit j: lane j), for `end`
        let mut nan_bits = [0u32; BLOCK];
        let mut base = 0;
        while base < $full {
            let nv = (($full - base) / L).min(BLOCK);
            start();
            for (k, slot) in keep.iter_mut().enumerate().take(nv) {
                let i = base + L * k;
                // (direct calls: a closure mapped over an array may stay out of line)
                let (ox, oy, oz) = (load(&rays.o[0], i), load(&rays.o[1], i), load(&rays.o[2], i));
                let (dx, dy, dz) = (load(&rays.d[0], i), load(&rays.d[1], i), load(&rays.d[2], i));
                let v = |k: usize, a: usize| load(&tris.v[k][a], i);
                let d = (dx, dy, dz);
                // stage 1 unfiltered; when `ok` clears every lane, stages 2-6 unfiltered
                // too, else all of stages 1-6 again behind the filter
                let (e1, e2, s) = rti_kernel!(@stage1 fsub, v, ox, oy, oz);
                let all = [e1.0, e1.1, e1.2, e2.0, e2.1, e2.2, s.0, s.1, s.2, dx, dy, dz];
                unfiltered[k] = ok(&all);
                *slot = if unfiltered[k] {
                    rti_kernel!(@stages26 fsub, fadd, fmul, fk, fmulk, e1, e2, s, d)
                } else {
                    let (e1, e2, s) = rti_kernel!(@stage1 sub, v, ox, oy, oz);
                    rti_kernel!(@stages26 sub, add, mul, nok, mulk, e1, e2, s, d)
                };
            }
            for (k, &[det, up, vp, tp]) in keep.iter().enumerate().take(nv) {
                let i = base + L * k;
                // stage 7
                let uv = if unfiltered[k] { fadd(up, vp) } else { add(up, vp) };
                // The compares of stage 7, with the det-sign select done by a sign flip:
                // when `det_ok` holds, det is neither ±0 nor NaN (threshold >= 0, checked
                // by the dispatch), so `det > 0 ? a <= b : b <= a` equals `a^s <= b^s`
                // with s = det's sign bit (negation is exact): `valid` is the same bit.
                let abs_det = $x::abs(det);
                let det_ok = if $backface { $x::lt(thr, det) } else { $x::lt(thr, abs_det) };
                let s = $x::sign(det);
                let nonneg = |x| $x::le(zero, $x::xor(x, s));
                let valid = $x::and_m(
                    $x::and_m(det_ok, nonneg(up)),
                    $x::and_m($x::and_m(nonneg(vp), $x::le($x::xor(uv, s), abs_det)), nonneg(tp)),
                );
                // the division last
                let (t, u, w) = if $recip {
                    let inv = div(one, det);
                    (mul(tp, inv), mul(up, inv), mul(vp, inv))
                } else {
                    (div(tp, det), div(up, det), div(vp, det))
                };
                let tmin = load(&rays.tmin, i);
                let tmax = load(&rays.tmax, i);
                let hit = $x::and_m(valid, $x::and_m($x::le(tmin, t), $x::le(t, tmax)));
                // SAFETY: lanes i..i + L are in bounds (checked by the caller).
                unsafe {
                    $x::flags(out.hit.as_mut_ptr(), i, hit);
                    $x::flags(out.valid.as_mut_ptr(), i, valid);
                }
                // NaN lanes are rare: canonicalise only when one of the results is NaN
                let canon = |x| $x::blend(x, nan, $x::unord(x, x));
                let nan_lanes = $x::bits($x::or_m($x::unord(t, u), $x::unord(w, w)));
                nan_bits[k] = nan_lanes;
                let (t, u, w) = if nan_lanes == 0 { (t, u, w) } else { (canon(t), canon(u), canon(w)) };
                store(&mut out.t, i, t);
                store(&mut out.u, i, u);
                store(&mut out.v, i, w);
            }
            end(base, nv, &nan_bits, &mut *out);
            base += L * nv;
        }
    }};
}

/// The slab stage table on one vector per step, for either batch shape, in the ops of `$x`.
/// `$load(column, i)` gives the lanes as binary32, `$round(x)` rounds a binary32 result to
/// the format, `$store(column, i, x)` writes results, `$up` steps up on the format's grid,
/// `$upn(x, n)` steps up `n` times (the conservative variants' widening), `$bcast` broadcasts
/// a ray value.
macro_rules! slab_kernel {
    // without a deferred rounding: `$round` everywhere
    ($x:ident, $s:expr, $rays:expr, $boxes:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $up:expr, $upn:expr, $bcast:expr) => {
        slab_kernel!($x, $s, $rays, $boxes, $out, $full, $load, $round, $store, $up, $upn, $bcast, defer $round, None::<&std::cell::Cell<$x::M>>)
    };
    // `defer $lround, $pending`: the non-directed loops round with `$lround`, which may leave
    // lanes wrong as long as it notes them in `$pending` (`Some(&Cell<mask>)`): those lanes'
    // outputs are made NaN, and the scalar model redoes them after the loop (`slab_redo`)
    ($x:ident, $s:expr, $rays:expr, $boxes:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $up:expr, $upn:expr, $bcast:expr, defer $lround:expr, $pending:expr) => {
        slab_kernel!($x, $s, $rays, $boxes, $out, $full, $load, $round, $store, $up, $upn, $bcast, defer $lround, $pending, rup |v| ($up)(($round)(v)))
    };
    // `rup $rup`: `$rup(x)` is `$up($round(x))` — the directed variant's rounding then grid
    // step — for any x, in whatever fewer operations the format has (binary16 on F16C: one
    // round trip, the step taken on the encoding between the two conversions)
    ($x:ident, $s:expr, $rays:expr, $boxes:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $up:expr, $upn:expr, $bcast:expr, defer $lround:expr, $pending:expr, rup $rup:expr) => {{
        // one loop per comparator and batch shape, so that neither is decided per vector
        let tof = $s.cfg.nan == SlabNan::TakeOnFalse;
        if $s.cfg.directed {
            match $rays {
                SlabRays::One(r) if tof => slab_kernel!(@dloop $x, $s, r, $boxes, $out, $full, $load, $round, $store, $rup, $bcast, true),
                SlabRays::One(r) => slab_kernel!(@dloop $x, $s, r, $boxes, $out, $full, $load, $round, $store, $rup, $bcast, false),
                // pairs of the directed variant are not eligible (see `slab_kernel_ray_*`)
                SlabRays::Pairs(r) => {
                    for k in 0..$full {
                        $out.set(k, $s.test(&r.get(k), &$boxes.get(k)));
                    }
                }
            }
            return;
        }
        match ($rays, tof) {
            (SlabRays::Pairs(r), false) => slab_kernel!(@loop $x, $s, pairs r, $boxes, $out, $full, $load, $lround, $pending, $store, $upn, $bcast, false),
            (SlabRays::Pairs(r), true) => slab_kernel!(@loop $x, $s, pairs r, $boxes, $out, $full, $load, $lround, $pending, $store, $upn, $bcast, true),
            (SlabRays::One(r), false) => slab_kernel!(@loop $x, $s, one r, $boxes, $out, $full, $load, $lround, $pending, $store, $upn, $bcast, false),
            (SlabRays::One(r), true) => slab_kernel!(@loop $x, $s, one r, $boxes, $out, $full, $load, $lround, $pending, $store, $upn, $bcast, true),
        }
    }};
    // per-batch preparation, hoisted out of the loop: column pointers; for one ray, each
    // axis's near and far plane columns (picked by the sign bit of 1/d) and the broadcast
    // origin, 1/d and t interval
    (@prep $x:ident, pairs $r:ident, $bmin:ident, $bmax:ident, $bcast:ident) => {
        (
            $r.o.each_ref().map(|c| c.as_ptr()),
            $r.inv_d.each_ref().map(|c| c.as_ptr()),
            $r.tmin.as_ptr(),
            $r.tmax.as_ptr(),
            true, // a lane's t interval may be NaN
        )
    };
    (@prep $x:ident, one $r:ident, $bmin:ident, $bmax:ident, $bcast:ident) => {{
        let neg = $r.inv_d.map(|v| $x::bits($x::sign_m($bcast(v))) != 0);
        let is_nan = |v| { let b = $bcast(v); $x::bits($x::unord(b, b)) != 0 };
        (
            std::array::from_fn::<_, 3, _>(|a| if neg[a] { $bmax[a] } else { $bmin[a] }),
            std::array::from_fn::<_, 3, _>(|a| if neg[a] { $bmin[a] } else { $bmax[a] }),
            ($r.o.map($bcast), $r.inv_d.map($bcast)),
            ($bcast($r.tmin), $bcast($r.tmax)),
            is_nan($r.tmin) || is_nan($r.tmax),
        )
    }};
    // axis a of lanes i..i + L: (near-plane t, far-plane t)
    (@plane $x:ident, pairs $prep:ident, $bmin:ident, $bmax:ident, $load:ident, $rd:ident, $a:expr, $i:ident) => {{
        let (o, inv) = ($load($prep.0[$a], $i), $load($prep.1[$a], $i));
        let tlo = $rd($x::mul($rd($x::sub($load($bmin[$a], $i), o)), inv));
        let thi = $rd($x::mul($rd($x::sub($load($bmax[$a], $i), o)), inv));
        // the sign bit of 1/d picks the near plane
        ($x::blend_sign(tlo, thi, inv), $x::blend_sign(thi, tlo, inv))
    }};
    (@plane $x:ident, one $prep:ident, $bmin:ident, $bmax:ident, $load:ident, $rd:ident, $a:expr, $i:ident) => {{
        let (o, inv) = ($prep.2 .0[$a], $prep.2 .1[$a]);
        (
            $rd($x::mul($rd($x::sub($load($prep.0[$a], $i), o)), inv)),
            $rd($x::mul($rd($x::sub($load($prep.1[$a], $i), o)), inv)),
        )
    }};
    // the batch's rays again, for the scalar model
    (@rays pairs $r:ident) => {
        SlabRays::Pairs($r)
    };
    (@rays one $r:ident) => {
        SlabRays::One($r)
    };
    // the t interval the chains start from
    (@limits pairs $prep:ident, $load:ident, $i:ident) => {
        ($load($prep.2, $i), $load($prep.3, $i))
    };
    (@limits one $prep:ident, $load:ident, $i:ident) => {
        $prep.3
    };
    // the directed variant, one ray against every box (see `Slab::trace_directed`, step for
    // step): the entry plane's difference rounded to nearest and stepped outward to a
    // bracket, the bracket end and the 1/d end chosen by their signs (the first by the ray's
    // direction, uniform; the second per lane), ends standing for ±∞ giving the unbounded
    // bound, the product stepped outward once. A parallel axis (uniform) tests the origin
    // against the slab. Lanes whose plane difference is NaN (its sign would pick an end) are
    // marked NaN and redone by the model, as are NaN outputs.
    (@dloop $x:ident, $s:expr, $r:ident, $boxes:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $rup:expr, $bcast:expr, $tof:expr) => {{
        let (s, boxes, out) = ($s, $boxes, $out);
        // `rup(x)` rounds x to the format, then steps up; `rdown` rounds, then steps down
        // (rounding to nearest commutes with negation)
        // (`$round` only through `rup`)
        let (load, store, rup, bcast) = ($load, $store, $rup, $bcast);
        let neg = |v| $x::xor(v, $x::splat(-0.0));
        let rdown = |v| neg(rup(neg(v)));
        let bmin = boxes.min.each_ref().map(|c| c.as_ptr());
        let bmax = boxes.max.each_ref().map(|c| c.as_ptr());
        let r = $r;
        use crate::Format as _;
        let f = &s.fmt;
        let prep = slab_kernel!(@prep $x, one r, bmin, bmax, bcast);
        let (top, bottom) = (f.from_f64(f64::INFINITY), f.from_f64(f64::NEG_INFINITY));
        let (vtop, vbottom) = (bcast(top), bcast(bottom));
        let is_top = |v| f.to_bits(v) == f.to_bits(top);
        let is_bottom = |v| f.to_bits(v) == f.to_bits(bottom);
        // per axis, uniform: direction sign, 1/d ends and whether each stands for ±∞
        let dneg: [bool; 3] = std::array::from_fn(|a| f.sign_bit(r.inv_d[a]));
        let inv_lo = r.inv_lo.map(bcast);
        let inv_hi = r.inv_hi.map(bcast);
        let lo_inf: [bool; 3] = std::array::from_fn(|a| is_bottom(r.inv_lo[a]));
        let hi_inf: [bool; 3] = std::array::from_fn(|a| is_top(r.inv_hi[a]));
        let all = $x::le($x::splat(0.0), $x::splat(0.0));
        let none = $x::lt($x::splat(0.0), $x::splat(0.0));
        let m = |b: bool| if b { all } else { none };
        let (o_hit, o_near, o_far) = (out.hit.as_mut_ptr(), out.t_near.as_mut_ptr(), out.t_far.as_mut_ptr());
        let mut nan_seen = 0;
        let mut i = 0;
        while i < $full {
            let (mut tn, mut tf) = prep.3;
            let mut outside = none;
            let mut bad = none;
            for a in 0..3 {
                let o = prep.2 .0[a];
                if r.parallel[a] {
                    let inside = $x::and_m($x::le(load(bmin[a], i), o), $x::le(o, load(bmax[a], i)));
                    outside = $x::or_m(outside, $x::not_m(inside));
                    continue;
                }
                // the plane differences, rounded and stepped to their bracket ends at once
                let de = $x::sub(load(prep.0[a], i), o);
                let dx = $x::sub(load(prep.1[a], i), o);
                // bracket end of the entry difference: d < 0 → its upper end, else its lower
                let (x_e, x_e_inf) = if dneg[a] {
                    let v = rup(de);
                    (v, $x::le(vtop, v))
                } else {
                    let v = rdown(de);
                    (v, $x::le(v, vbottom))
                };
                let (x_x, x_x_inf) = if dneg[a] {
                    let v = rdown(dx);
                    (v, $x::le(v, vbottom))
                } else {
                    let v = rup(dx);
                    (v, $x::le(vtop, v))
                };
                // a NaN difference (its bracket end is NaN too: a step keeps NaN)
                bad = $x::or_m(bad, $x::unord(x_e, x_x));
                // the 1/d end by the bracket end's sign: negative → inv_hi (entry) / inv_lo (exit)
                let inv_e = $x::blend_sign(inv_lo[a], inv_hi[a], x_e);
                let inv_x = $x::blend_sign(inv_hi[a], inv_lo[a], x_x);
                // whether the chosen 1/d end stands for ±∞ (the usual ray's ends are finite:
                // no lane's is, and the uniform test skips the per-lane choice)
                let (inv_e_inf, inv_x_inf) = if lo_inf[a] || hi_inf[a] {
                    (
                        $x::blend_m(m(lo_inf[a]), m(hi_inf[a]), $x::sign_m(x_e)),
                        $x::blend_m(m(hi_inf[a]), m(lo_inf[a]), $x::sign_m(x_x)),
                    )
                } else {
                    (none, none)
                };
                let t_entry = $x::blend(rdown($x::mul(x_e, inv_e)), vbottom, $x::or_m(x_e_inf, inv_e_inf));
                let t_exit = $x::blend(rup($x::mul(x_x, inv_x)), vtop, $x::or_m(x_x_inf, inv_x_inf));
                (tn, tf) = slab_kernel!(@compare $x, $tof, (tn, tf), t_entry, t_exit);
            }
            tn = $x::blend(tn, $x::canonical_nan(), bad);
            let hit = $x::and_m($x::not_m(outside), $x::le(tn, tf));
            // SAFETY: lanes i..i + L are in bounds.
            unsafe { $x::flags(o_hit, i, hit) };
            store(o_near, i, tn);
            store(o_far, i, tf);
            nan_seen |= $x::bits($x::unord(tn, tf));
            i += $x::LANES;
        }
        if nan_seen != 0 {
            // SAFETY: lanes 0..full are in bounds (as above).
            unsafe { slab_redo(s, SlabRays::One(r), boxes, (o_hit, o_near, o_far), $full) };
        }
    }};
    (@loop $x:ident, $s:expr, $shape:ident $r:ident, $boxes:expr, $out:expr, $full:expr, $load:expr, $round:expr, $pending:expr, $store:expr, $upn:expr, $bcast:expr, $tof:expr) => {{
        let (s, boxes, out) = ($s, $boxes, $out);
        let (load, rd, store, upn, bcast) = ($load, $round, $store, $upn, $bcast);
        let pending = $pending;
        let none = $x::lt($x::splat(0.0), $x::splat(0.0));
        // n steps down are n steps up mirrored through the sign (negation is exact)
        let neg = |v| $x::xor(v, $x::splat(-0.0));
        let down_n = |v, n| neg(upn(neg(v), n));
        let bmin = boxes.min.each_ref().map(|c| c.as_ptr());
        let bmax = boxes.max.each_ref().map(|c| c.as_ptr());
        let prep = slab_kernel!(@prep $x, $shape $r, bmin, bmax, bcast);
        let _ = bcast; // the pairs shape broadcasts nothing
        let (o_hit, o_near, o_far) = (out.hit.as_mut_ptr(), out.t_near.as_mut_ptr(), out.t_far.as_mut_ptr());
        let widen = s.cfg.widen_ulps;
        // vmaxps / vminps return their second operand (the running t) when either is NaN,
        // and the widening steps keep a number a number, so the plain comparator's chains
        // end in NaN only if they start from a NaN t interval: a one-ray batch with a
        // number interval needs no NaN check per vector (take-on-false chains can take a
        // NaN plane and always check)
        // the conservative variant's guard: a stage-1 subtract that overflowed is NaN in the
        // model, and the plane it feeds is dropped; the kernel leaves it ±∞, which differs
        // from dropping it only when it leaves t_near = +∞ or t_far = −∞. Lanes with a
        // non-finite chain end (before widening) are marked NaN and redone by the model
        // (the reciprocal's guard is applied when the ray is prepared)
        let guard = s.cfg.guard;
        let check_nan = $tof || prep.4 || guard || pending.is_some();
        let (r, model) = ($r, s);
        let mut nan_seen = 0;
        let mut i = 0;
        while i < $full {
            let planes = [
                slab_kernel!(@plane $x, $shape prep, bmin, bmax, load, rd, 0, i),
                slab_kernel!(@plane $x, $shape prep, bmin, bmax, load, rd, 1, i),
                slab_kernel!(@plane $x, $shape prep, bmin, bmax, load, rd, 2, i),
            ];
            let lim = slab_kernel!(@limits $shape prep, load, i);
            let (mut tn, tf) = slab_kernel!(@ends $x, lim, planes, $tof, widen, guard, upn, down_n);
            if let Some(p) = pending {
                // the lanes the deferred rounding may have got wrong: redone by the model
                tn = $x::blend(tn, $x::canonical_nan(), p.replace(none));
            }
            // SAFETY: lanes i..i + L are in bounds.
            unsafe { $x::flags(o_hit, i, $x::le(tn, tf)) };
            store(o_near, i, tn);
            store(o_far, i, tf);
            // NaN lanes are rare, and their bits depend on where the NaN came from (the
            // model canonicalises an arithmetic NaN but passes a NaN t interval through a
            // comparator as it is, payload and all, which binary16's widening would quiet):
            // noted here, done again by the scalar model after the loop
            if check_nan {
                nan_seen |= $x::bits($x::unord(tn, tf));
            }
            i += $x::LANES;
        }
        if nan_seen != 0 {
            // SAFETY: lanes 0..full are in bounds (as above).
            unsafe { slab_redo(model, slab_kernel!(@rays $shape r), boxes, (o_hit, o_near, o_far), $full) };
        }
    }};
    // one step of the compare unit's chains: the running (t_near, t_far) `$t` against a plane's
    // near and far t, by the variant's comparator
    (@compare $x:ident, $tof:expr, $t:expr, $near:expr, $far:expr) => {{
        let ((tn, tf), near, far) = ($t, $near, $far);
        if $tof {
            // t = (x <= t) ? t : x (near), (t <= x) ? t : x (far)
            ($x::blend(near, tn, $x::le(near, tn)), $x::blend(far, tf, $x::le(tf, far)))
        } else {
            // t = (x > t) ? x : t (near), (x < t) ? x : t (far): exactly vmaxps(x, t)
            // and vminps(x, t), which return the second operand on NaN or equality
            ($x::max(near, tn), $x::min(far, tf))
        }
    }};
    // the comparator chains over the three planes from the t interval `$lim`, then the
    // widening by `$widen` grid steps and the conservative guard: (t_near, t_far)
    (@ends $x:ident, $lim:expr, $planes:expr, $tof:expr, $widen:expr, $guard:expr, $upn:ident, $down_n:ident) => {{
        let (mut tn, mut tf) = $lim;
        for &(near, far) in &$planes {
            (tn, tf) = slab_kernel!(@compare $x, $tof, (tn, tf), near, far);
        }
        let (ends, widen): (_, i32) = ((tn, tf), $widen);
        if widen > 0 {
            tn = $down_n(tn, widen.unsigned_abs());
            tf = $upn(tf, widen.unsigned_abs());
        } else if widen < 0 {
            tn = $upn(tn, widen.unsigned_abs());
            tf = $down_n(tf, widen.unsigned_abs());
        }
        if $guard {
            let zero = $x::splat(0.0);
            let unbounded = $x::unord($x::mul(ends.0, zero), $x::mul(ends.1, zero));
            tn = $x::blend(tn, $x::canonical_nan(), unbounded);
        }
        (tn, tf)
    }};
    // several round-to-nearest variants of one format on one ray and the same boxes, their
    // planes computed once (they compute them alike: the same ray, the same operations and
    // rounding; the caller checked), then per variant `@loop`'s chains, widening, guard,
    // deferred-rounding mark, stores and NaN check, with its comparator; each variant's NaN
    // lanes redone by its own model after the loop — each variant's outputs bit for bit those
    // of `@loop` with `one r` alone
    (@mloop $x:ident, $group:expr, $r:ident, $boxes:expr, $outs:expr, $full:expr, $load:expr, $lround:expr, $pending:expr, $store:expr, $upn:expr, $bcast:expr) => {{
        let (group, boxes, outs) = ($group, $boxes, $outs);
        let (load, rd, store, upn, bcast) = ($load, $lround, $store, $upn, $bcast);
        let pending = $pending;
        let none = $x::lt($x::splat(0.0), $x::splat(0.0));
        let neg = |v| $x::xor(v, $x::splat(-0.0));
        let down_n = |v, n| neg(upn(neg(v), n));
        let bmin = boxes.min.each_ref().map(|c| c.as_ptr());
        let bmax = boxes.max.each_ref().map(|c| c.as_ptr());
        let r = $r;
        let prep = slab_kernel!(@prep $x, one r, bmin, bmax, bcast);
        assert!(group.len() == outs.len() && group.len() <= MAX_SHARED, "slab_kernel: a group of another shape");
        // per variant: comparator, widening, guard, whether it checks for NaN (as `@loop`),
        // output columns
        let cfg: [(bool, i32, bool, bool); MAX_SHARED] = std::array::from_fn(|j| match group.get(j) {
            Some(s) => {
                let tof = s.cfg.nan == SlabNan::TakeOnFalse;
                (tof, s.cfg.widen_ulps, s.cfg.guard, tof || prep.4 || s.cfg.guard || pending.is_some())
            }
            None => (false, 0, false, false),
        });
        let mut each = outs.iter_mut();
        let ptrs: [_; MAX_SHARED] = std::array::from_fn(|_| {
            each.next().map(|o| (o.hit.as_mut_ptr(), o.t_near.as_mut_ptr(), o.t_far.as_mut_ptr()))
        });
        let mut nan_seen = [0; MAX_SHARED];
        let mut i = 0;
        while i < $full {
            let planes = [
                slab_kernel!(@plane $x, one prep, bmin, bmax, load, rd, 0, i),
                slab_kernel!(@plane $x, one prep, bmin, bmax, load, rd, 1, i),
                slab_kernel!(@plane $x, one prep, bmin, bmax, load, rd, 2, i),
            ];
            // the lanes the deferred rounding may have got wrong, for every variant
            let marked = pending.map(|c| c.replace(none));
            for (j, p) in ptrs.iter().enumerate() {
                let Some((o_hit, o_near, o_far)) = *p else { break };
                let (tof, widen, guard, check_nan) = cfg[j];
                let (mut tn, tf) = slab_kernel!(@ends $x, prep.3, planes, tof, widen, guard, upn, down_n);
                if let Some(m) = marked {
                    tn = $x::blend(tn, $x::canonical_nan(), m);
                }
                // SAFETY: lanes i..i + L are in bounds (the caller checked every column).
                unsafe { $x::flags(o_hit, i, $x::le(tn, tf)) };
                store(o_near, i, tn);
                store(o_far, i, tf);
                if check_nan {
                    nan_seen[j] |= $x::bits($x::unord(tn, tf));
                }
            }
            i += $x::LANES;
        }
        for (j, p) in ptrs.iter().enumerate() {
            let Some(p) = *p else { break };
            if nan_seen[j] != 0 {
                // SAFETY: lanes 0..full are in bounds (as above).
                unsafe { slab_redo(group[j], SlabRays::One(r), boxes, p, $full) };
            }
        }
    }};
}

/// [`slab_kernel!`] with the format's subnormal rule: as it is under IEEE subnormals; under
/// FTZ every operand read (columns and broadcast ray values) and every rounded result
/// flushed in the lanes (a lane below `$min`, the smallest normal, becomes zero of its
/// sign), and a grid step that lands strictly between 0 and `$min` goes on to `$min` (up
/// from ±0) or to −0 (up from −`$min`), the model's `next_up`. The model's comparators read a
/// t limit flushed but pass it on as it is, so a limit that is a nonzero subnormal encoding
/// (`$raw_sub`) sends its lane, or the whole one-ray batch, to the scalar model.
macro_rules! slab_ftz {
    ($x:ident, $s:expr, $rays:expr, $boxes:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $up:expr, $upn:expr, $bcast:expr, $min:expr, $raw_sub:expr) => {
        slab_ftz!($x, $s, $rays, $boxes, $out, $full, $load, $round, $store, $up, $upn, $bcast, $min, $raw_sub, defer $round, None::<&std::cell::Cell<$x::M>>)
    };
    ($x:ident, $s:expr, $rays:expr, $boxes:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $up:expr, $upn:expr, $bcast:expr, $min:expr, $raw_sub:expr, defer $lround:expr, $pending:expr) => {
        slab_ftz!($x, $s, $rays, $boxes, $out, $full, $load, $round, $store, $up, $upn, $bcast, $min, $raw_sub, defer $lround, $pending, rup |v| ($up)(($round)(v)))
    };
    // `defer`: as `slab_kernel!`'s, with IEEE subnormals only (under FTZ, `$round`); `rup`:
    // as `slab_kernel!`'s, with IEEE subnormals only (under FTZ, the flushing step of the
    // flushed rounding)
    ($x:ident, $s:expr, $rays:expr, $boxes:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $up:expr, $upn:expr, $bcast:expr, $min:expr, $raw_sub:expr, defer $lround:expr, $pending:expr, rup $rup:expr) => {{
        let (s, rays, boxes, out, full) = ($s, $rays, $boxes, $out, $full);
        if s.fmt.opts.subnormals != Subnormals::Ftz {
            slab_kernel!($x, s, rays, boxes, out, full, $load, $round, $store, $up, $upn, $bcast, defer $lround, $pending, rup $rup);
        } else {
            let raw_sub = $raw_sub;
            if let SlabRays::One(r) = rays {
                if raw_sub(r.tmin) || raw_sub(r.tmax) {
                    return s.batch_ray(r, boxes, out);
                }
            }
            let (load, round, up, bcast) = ($load, $round, $up, $bcast);
            let (min, zero) = ($x::splat($min), $x::splat(0.0));
            let flush = move |x| $x::blend(x, $x::sign(x), $x::lt($x::abs(x), min));
            let up_ftz = move |v| {
                let r = up(v);
                let a = $x::abs(r);
                let tiny = $x::and_m($x::lt(zero, a), $x::lt(a, min));
                $x::blend(r, $x::blend(min, $x::splat(-0.0), $x::lt(v, zero)), tiny)
            };
            slab_kernel!(
                $x,
                s,
                rays,
                boxes,
                &mut *out,
                full,
                |c, i| flush(load(c, i)),
                |x| flush(round(x)),
                $store,
                up_ftz,
                |v, n: u32| (0..n).fold(v, |v, _| up_ftz(v)),
                |v| flush(bcast(v))
            );
            if let SlabRays::Pairs(r) = rays {
                for k in 0..full {
                    if raw_sub(r.tmin[k]) || raw_sub(r.tmax[k]) {
                        out.set(k, s.test(&r.get(k), &boxes.get(k)));
                    }
                }
            }
        }
    }};
}

/// The lanes of `0..full` with a NaN output, again by the scalar model (the slab kernels'
/// rare NaN path, kept out of their loops).
///
/// # Safety
/// The output pointers must be valid for lanes `0..full`.
#[cold]
#[inline(never)]
pub(super) unsafe fn slab_redo<F: crate::Format>(
    s: &Slab<F>,
    rays: SlabRays<F::V>,
    boxes: &BoxesSoa<F::V>,
    (hit, near, far): (*mut bool, *mut F::V, *mut F::V),
    full: usize,
) {
    for k in 0..full {
        // SAFETY: k is in bounds (the caller).
        let nan = unsafe { s.fmt.is_nan(*near.add(k)) || s.fmt.is_nan(*far.add(k)) };
        if nan {
            let ray = match rays {
                SlabRays::Pairs(r) => r.get(k),
                SlabRays::One(r) => *r,
            };
            let o = s.test(&ray, &boxes.get(k));
            // SAFETY: as above.
            unsafe {
                *hit.add(k) = o.hit;
                *near.add(k) = o.t_near;
                *far.add(k) = o.t_far;
            }
        }
    }
}

/// The kernels (RTI and slab) of one instruction set: binary32 and binary16, or binary16 only.
macro_rules! kernels_for {
    ($x:ident, $f32feat:literal, $f16feat:literal) => {
        pub(in crate::simd) mod $x {
            use super::super::isa::$x;
            use super::*;
            kernels_for!(@f32 $x, $f32feat);
            kernels_for!(@f16 $x, $f16feat);
        }
    };
    ($x:ident, binary16 $f16feat:literal) => {
        pub(in crate::simd) mod $x {
            use super::super::isa::$x;
            use super::*;
            kernels_for!(@f16 $x, $f16feat);
        }
    };
    (@f32 $x:ident, $f32feat:literal) => {
        kernels_for!(@format $x, $f32feat, rti_f32, slab_f32, slab_f32_shared, Ieee<F32Native>, f32, load32, store32,
            |x| x, |v| $x::next_up(v), |v, n: u32| $x::next_up_n(v, n), |x: f32| $x::splat(x), |r: &Rti<Ieee<F32Native>>| r.det_thr,
            f32::MIN_POSITIVE, |v: f32| v != 0.0 && v.abs() < f32::MIN_POSITIVE);
    };
    (@f16 $x:ident, $f16feat:literal) => {
        kernels_for!(@format $x, $f16feat, rti_f16, slab_f16, slab_f16_shared, Ieee<F16Half>, f16, load16, store16,
            |v| $x::round16(v), |v| $x::next_up16(v), |v, n: u32| (0..n).fold(v, |v, _| $x::next_up16(v)), |x: f16| $x::splat16(x),
            |r: &Rti<Ieee<F16Half>>| r.det_thr.to_f32(), f16::MIN_POSITIVE.to_f32(), |v: f16| v.to_bits() & 0x7c00 == 0 && v.to_bits() & 0x3ff != 0);
    };
    // one format's RTI and slab kernels: its column type, loads and stores, rounding, grid
    // step, ray broadcast, det threshold (as the lanes hold it), and smallest normal (the RTI
    // kernel under FTZ flushes every operand read and every rounded result in the lanes: a
    // lane below it becomes zero of its sign)
    (@format $x:ident, $feat:literal, $rti:ident, $slab:ident, $shared:ident, $fmt:ty, $v:ty, $load:ident, $store:ident,
     $round:expr, $up:expr, $upn:expr, $bcast:expr, $thr:expr, $min_normal:expr, $raw_sub:expr) => {
        #[target_feature(enable = $feat)]
        pub fn $rti(rti: &Rti<$fmt>, rays: &RaysSoa<$v>, tris: &TrisSoa<$v>, out: &mut HitsSoa<$v>, full: usize) {
            // SAFETY (loads and stores): the caller checked that every column holds
            // `full` lanes; the column types are plain values.
            macro_rules! run {
                ($ld:expr, $rd:expr) => {
                    rti_kernel!(
                        $x,
                        rti,
                        rays,
                        tris,
                        out,
                        full,
                        $ld,
                        $rd,
                        |c: &mut Vec<$v>, i: usize, x| unsafe { $x::$store(c.as_mut_ptr(), i, x) },
                        ($thr)(rti),
                        || {},
                        |_: usize, _: usize, _: &[u32; 8], _: &mut HitsSoa<$v>| {}
                    )
                };
            }
            let load = |c: &Vec<$v>, i: usize| unsafe { $x::$load(c.as_ptr(), i) };
            if rti.fmt.opts.subnormals == Subnormals::Ftz {
                // (the comparator reads the threshold flushed, but det is ±0 or normal
                // here, so a subnormal threshold decides as zero does)
                let flush = |x| $x::blend(x, $x::sign(x), $x::lt($x::abs(x), $x::splat($min_normal)));
                let round = $round;
                run!(|c: &Vec<$v>, i: usize| flush(load(c, i)), |x| flush(round(x)));
            } else {
                run!(load, $round);
            }
        }

        #[target_feature(enable = $feat)]
        pub fn $slab(s: &Slab<$fmt>, rays: SlabRays<$v>, boxes: &BoxesSoa<$v>, out: &mut SlabOutSoa<$v>, full: usize) {
            // SAFETY (loads and stores): as above.
            slab_ftz!(
                $x,
                s,
                rays,
                boxes,
                out,
                full,
                |c: *const $v, i: usize| unsafe { $x::$load(c, i) },
                $round,
                |c: *mut $v, i: usize, x| unsafe { $x::$store(c, i, x) },
                $up,
                $upn,
                $bcast,
                $min_normal,
                $raw_sub,
                defer $round,
                None::<&std::cell::Cell<$x::M>>,
                // binary32: rounding is the identity; binary16: `next_up16` rounds to nearest
                // in its conversion to the encoding, so it is the step of the rounding
                rup $up
            );
        }

        // (`v8r`'s is unused: the dispatch keeps `v8`'s F16C rounding)
        shared_slab_fn!($x, $feat, $shared, $fmt, $v,
            |c: *const $v, i: usize| unsafe { $x::$load(c, i) },
            $round,
            |c: *mut $v, i: usize, x| unsafe { $x::$store(c, i, x) },
            $upn, $bcast);
    };
}

/// A slab kernel for several round-to-nearest variants of one format on one ray and the same
/// boxes, their planes computed once (`slab_kernel!`'s `@mloop`, no deferred rounding; IEEE
/// subnormals: the caller checked that every variant qualifies and that they share the format
/// and the prepared ray): each `outs[j]` bit for bit the format's slab kernel of `group[j]`
/// alone. `$load`, `$round`, `$store`, `$upn`, `$bcast` as that kernel's.
macro_rules! shared_slab_fn {
    ($x:ident, $feat:literal, $name:ident, $fmt:ty, $v:ty, $load:expr, $round:expr, $store:expr, $upn:expr, $bcast:expr) => {
        /// The format's slab kernel for several round-to-nearest variants on one ray and the
        /// same boxes, their planes computed once (`shared_slab_fn!`).
        #[allow(dead_code)]
        #[target_feature(enable = $feat)]
        pub fn $name(
            group: &[&Slab<$fmt>],
            r: &crate::slab::SlabRay<$v>,
            boxes: &BoxesSoa<$v>,
            outs: &mut [SlabOutSoa<$v>],
            full: usize,
        ) {
            // SAFETY (loads and stores): the caller checked that every column holds `full`
            // lanes; the column types are plain values.
            slab_kernel!(@mloop $x, group, r, boxes, outs, full, $load, $round, None::<&std::cell::Cell<$x::M>>, $store, $upn, $bcast);
        }
    };
}

kernels_for!(v8, "avx2", "avx2,f16c");
// binary16 rounded in binary32 lanes instead of an F16C round trip per operation (measured
// beside `v8` by `raypipe speed`; the dispatch keeps `v8`, docs/speed.md)
kernels_for!(v8r, binary16 "avx2,f16c");
kernels_for!(v16, "avx512f", "avx512f,avx2");
kernels_for!(v32h, binary16 "avx512fp16,avx512bw,avx512f");

/// The RTI kernels of the narrow `eEmM` formats (M ≤ 24 and E ≤ 10) on the binary64 lanes
/// of one instruction set (`v4d`, `v8d`): the same stage table, every operation in
/// binary64 then rounded to the format in the lanes, its whole range included
/// ([`isa::v4d::round_full`]), and stages 2-7 by the split alone when the range filter
/// ([`isa::v4d::fast_ok`]) proves them in range (see [`crate::format::narrow`]).
macro_rules! narrow_for {
    ($x:ident, $feat:literal, $rtifeat:literal) => {
        pub(in crate::simd) mod $x {
            use super::super::isa::$x;
            use super::*;
            use crate::format::narrow::Narrow;
            use crate::format::Soft;

            /// One format's RTI kernel on lanes `0..full`: its column loads and stores.
            macro_rules! narrow_rti {
                ($rti:expr, $rays:expr, $tris:expr, $out:expr, $full:expr, $v:ty, $load:expr, $store:expr) => {{
                    let (rti, rays, tris) = ($rti, $rays, $tris);
                    let n: &Narrow =
                        &super::super::select::narrow_of(&rti.fmt).expect("the dispatch checked the format");
                    let load = $load;
                    rti_kernel!(
                        $x,
                        rti,
                        rays,
                        tris,
                        $out,
                        $full,
                        |c: &Vec<$v>, i: usize| $x::flush(load(c, i), n),
                        |x| $x::round_full(x, n),
                        |x| $x::split(x, n),
                        |b| $x::split_k(b, n),
                        |a, b, bk| $x::split_mul(a, b, bk),
                        |v: &[_; 12]| $x::fast_ok(v, n),
                        $store,
                        super::super::select::narrow_thr(rti, n),
                        || {},
                        |_: usize, _: usize, _: &[u32; 8], _: &mut HitsSoa<$v>| {}
                    )
                }};
            }

            /// The `eEmM` RTI kernel on lanes `0..full`.
            #[target_feature(enable = $rtifeat)]
            pub fn rti_soft(
                rti: &Rti<Ieee<Soft>>,
                rays: &RaysSoa<u64>,
                tris: &TrisSoa<u64>,
                out: &mut HitsSoa<u64>,
                full: usize,
            ) {
                let n: &Narrow = &super::super::select::narrow_of(&rti.fmt).expect("the dispatch checked the format");
                // SAFETY (loads and stores): as above. One loop per encoding shape, so that
                // neither is decided per load.
                if n.e8 {
                    narrow_rti!(
                        rti,
                        rays,
                        tris,
                        out,
                        full,
                        u64,
                        |c: &Vec<u64>, i: usize| unsafe { $x::load_e8(c.as_ptr(), i, n) },
                        |c: &mut Vec<u64>, i: usize, x| unsafe { $x::store_e8(c.as_mut_ptr(), i, x, n) }
                    );
                } else {
                    narrow_rti!(
                        rti,
                        rays,
                        tris,
                        out,
                        full,
                        u64,
                        |c: &Vec<u64>, i: usize| unsafe { $x::load_soft(c.as_ptr(), i, n) },
                        |c: &mut Vec<u64>, i: usize, x| unsafe { $x::store_soft(c.as_mut_ptr(), i, x, n) }
                    );
                }
            }

            /// The `eEmM` slab kernel (pairs, or one ray against every box) on lanes
            /// `0..full`, every variant (the directed one on one-ray batches), either
            /// subnormal mode (`slab_kernel_soft`, `slab_ray_kernel_soft`). Under FTZ the
            /// operands read flushed; a t limit that is a nonzero subnormal encoding (the
            /// model's comparators read it as zero but pass it on as it is) sends its lanes
            /// (one ray: the batch) to the scalar model.
            #[target_feature(enable = $feat)]
            pub fn slab_soft(
                s: &Slab<Ieee<Soft>>,
                rays: SlabRays<u64>,
                boxes: &BoxesSoa<u64>,
                out: &mut SlabOutSoa<u64>,
                full: usize,
            ) {
                let n: &Narrow = &super::super::select::narrow_of(&s.fmt).expect("the dispatch checked the format");
                let f = s.fmt;
                // the non-directed loops round by the split alone and note the lanes outside
                // its range (`split_noting`), which the scalar model redoes
                let pending = std::cell::Cell::new($x::lt($x::splat(0.0), $x::splat(0.0)));
                // SAFETY (loads and stores): the caller checked that every column holds
                // `full` lanes.
                slab_ftz!(
                    $x,
                    s,
                    rays,
                    boxes,
                    out,
                    full,
                    |c: *const u64, i: usize| unsafe { $x::load_soft(c, i, n) },
                    |x| $x::round_full(x, n),
                    |c: *mut u64, i: usize, x| unsafe { $x::store_soft(c, i, x, n) },
                    |v| $x::next_up_soft(v, n),
                    |v, k: u32| $x::next_up_soft_n(v, k, n),
                    |v: u64| $x::splat(f.to_f64(v)),
                    n.min_normal,
                    |v: u64| n.lay.is_subnormal(v),
                    defer | x | $x::split_noting(x, n, &pending),
                    Some(&pending)
                );
            }

            /// [`slab_soft`] of several round-to-nearest variants on one ray and the same
            /// boxes, their planes computed once (`slab_kernel!`'s `@mloop`; IEEE subnormals:
            /// the caller checked that every variant qualifies and that they share the format
            /// and the prepared ray): each `outs[j]` bit for bit `slab_soft` of `group[j]`.
            #[target_feature(enable = $feat)]
            pub fn slab_soft_shared(
                group: &[&Slab<Ieee<Soft>>],
                r: &crate::slab::SlabRay<u64>,
                boxes: &BoxesSoa<u64>,
                outs: &mut [SlabOutSoa<u64>],
                full: usize,
            ) {
                let n: &Narrow = &super::super::select::narrow_of(&group[0].fmt).expect("the dispatch checked the format");
                let f = group[0].fmt;
                let pending = std::cell::Cell::new($x::lt($x::splat(0.0), $x::splat(0.0)));
                // SAFETY (loads and stores): the caller checked that every column holds
                // `full` lanes.
                slab_kernel!(
                    @mloop $x,
                    group,
                    r,
                    boxes,
                    outs,
                    full,
                    |c: *const u64, i: usize| unsafe { $x::load_soft(c, i, n) },
                    |x| $x::split_noting(x, n, &pending),
                    Some(&pending),
                    |c: *mut u64, i: usize, x| unsafe { $x::store_soft(c, i, x, n) },
                    |v, k: u32| $x::next_up_soft_n(v, k, n),
                    |v: u64| $x::splat(f.to_f64(v))
                );
            }

            /// One operation of an `eEmM` format on lanes `0..full`: `out[i] = a[i] op b[i]`,
            /// each result rounded by [`isa::v4d::round_full`] (the RTI kernel's rounding).
            #[target_feature(enable = $feat)]
            pub fn op_soft(f: &Ieee<Soft>, op: crate::stage::Op, a: &[u64], b: &[u64], out: &mut [u64], full: usize) {
                use crate::stage::Op;
                let n = &super::super::select::narrow_of(f).expect("the dispatch checked the format");
                let mut i = 0;
                while i < full {
                    // SAFETY: the caller checked that every slice holds `full` lanes.
                    let (x, y) = unsafe { ($x::load_soft(a.as_ptr(), i, n), $x::load_soft(b.as_ptr(), i, n)) };
                    let (x, y) = ($x::flush(x, n), $x::flush(y, n));
                    let rd = |v| $x::round_full(v, n);
                    let r = match (op, f.opts.div) {
                        (Op::Add, _) => rd($x::add(x, y)),
                        (Op::Sub, _) => rd($x::sub(x, y)),
                        (Op::Mul, _) => rd($x::mul(x, y)),
                        (Op::Div, DivMode::Divide) => rd($x::div(x, y)),
                        (Op::Div, DivMode::RecipMul) => {
                            let inv = rd($x::div($x::splat(1.0), y));
                            rd($x::mul(x, inv))
                        }
                        (Op::Logic, _) => unreachable!("the dispatch refuses Logic"),
                    };
                    // SAFETY: as above; a NaN lane is stored as the canonical NaN.
                    unsafe { $x::store_soft(out.as_mut_ptr(), i, r, n) };
                    i += $x::LANES;
                }
            }
        }
    };
}

/// The bf16 RTI kernel on binary32 lanes of one instruction set (`v8`, `v16`): the scalar
/// model's own arithmetic (each operation in binary32, then rounded to bf16 in the
/// integer lanes), the operand read and the result write flushed under FTZ.
macro_rules! bf16_for {
    ($m:ident, $x:ident, $feat:literal) => {
        pub(in crate::simd) mod $m {
            use super::super::isa::$x;
            use super::*;
            use crate::format::Bf16;

            /// The bf16 RTI kernel on lanes `0..full`.
            #[target_feature(enable = $feat)]
            pub fn rti_bf16(
                rti: &Rti<Ieee<Bf16>>,
                rays: &RaysSoa<u16>,
                tris: &TrisSoa<u16>,
                out: &mut HitsSoa<u16>,
                full: usize,
            ) {
                let ftz = rti.fmt.opts.subnormals == Subnormals::Ftz;
                let thr = rti.fmt.to_f64(rti.det_thr) as f32;
                let thr = if ftz && thr.abs() < f32::MIN_POSITIVE { 0.0 } else { thr };
                // SAFETY (loads and stores): the caller checked that every column holds
                // `full` lanes; the column types are plain values.
                rti_kernel!(
                    $x,
                    rti,
                    rays,
                    tris,
                    out,
                    full,
                    |c: &Vec<u16>, i: usize| $x::flush_bf16(unsafe { $x::load_bf16(c.as_ptr(), i) }, ftz),
                    |x| $x::flush_bf16($x::round_bf16(x), ftz),
                    |c: &mut Vec<u16>, i: usize, x| unsafe { $x::store_bf16(c.as_mut_ptr(), i, x) },
                    thr,
                    || {},
                    |_: usize, _: usize, _: &[u32; 8], _: &mut HitsSoa<u16>| {}
                );
            }

            /// The bf16 slab kernel on lanes `0..full`, IEEE subnormals or FTZ ([`slab_ftz!`]).
            #[target_feature(enable = $feat)]
            pub fn slab_bf16(
                s: &Slab<Ieee<Bf16>>,
                rays: SlabRays<u16>,
                boxes: &BoxesSoa<u16>,
                out: &mut SlabOutSoa<u16>,
                full: usize,
            ) {
                // SAFETY (loads and stores): the caller checked that every column holds
                // `full` lanes; the column types are plain values.
                slab_ftz!(
                    $x,
                    s,
                    rays,
                    boxes,
                    out,
                    full,
                    |c: *const u16, i: usize| unsafe { $x::load_bf16(c, i) },
                    |x| $x::round_bf16(x),
                    |c: *mut u16, i: usize, x| unsafe { $x::store_bf16(c, i, x) },
                    |v| $x::next_up_bf16(v),
                    |v, n: u32| $x::next_up_bf16_n(v, n),
                    |x: u16| $x::splat(f32::from_bits((x as u32) << 16)),
                    f32::MIN_POSITIVE,
                    |v: u16| v & 0x7f80 == 0 && v & 0x7f != 0
                );
            }

            shared_slab_fn!(
                $x,
                $feat,
                slab_bf16_shared,
                Ieee<Bf16>,
                u16,
                |c: *const u16, i: usize| unsafe { $x::load_bf16(c, i) },
                |x| $x::round_bf16(x),
                |c: *mut u16, i: usize, x| unsafe { $x::store_bf16(c, i, x) },
                |v, n: u32| $x::next_up_bf16_n(v, n),
                |x: u16| $x::splat(f32::from_bits((x as u32) << 16))
            );
        }
    };
}

bf16_for!(b8, v8, "avx2");
bf16_for!(b16, v16, "avx512f,avx2");

narrow_for!(v4d, "avx2,fma", "avx2,fma");
// the RTI kernel's range filter uses AVX-512DQ's `vrangepd` ([`isa::v8d::fast_ok`])
narrow_for!(v8d, "avx512f,avx2", "avx512f,avx512dq,avx2");
