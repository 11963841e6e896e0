//! raypipe's models behind a C ABI: a live reference model that C programs, SystemVerilog
//! testbenches (DPI-C) and VHDL testbenches (GHDL's VHPIDIRECT) call while they run.
//!
//! A unit handle ([`rp_unit_new`]) names a unit (`rti`, `slab`, `op`), a format and options
//! with the CLI's own strings. Every call evaluates rows laid out as the vector files' rows
//! (docs/vectors.md): an input row is a `*_inputs.hex` row without its class column, an output
//! row a `*_expected.hex` row, a stage row a `*_stages.hex` row; each value is the format's
//! encoding in the low bits of a `uint64_t` (flags 0 or 1). The bits are those of the models
//! the vector sets are written from.
//!
//! Errors: every function returns `RP_OK` (0) or an error code, and [`rp_last_error`] says
//! what went wrong in words; no call panics across the boundary (every entry catches an
//! unwinding panic and reports `RP_ERR_INTERNAL`), none aborts on bad input.

use std::cell::RefCell;
use std::ffi::{c_char, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

pub mod cover;
pub mod unit;

/// The call succeeded.
pub const RP_OK: i32 = 0;
/// A bad argument: an unknown unit, format or option, an encoding wider than the format, an
/// op code out of range.
pub const RP_ERR_ARGUMENT: i32 = 1;
/// A null pointer where one is required.
pub const RP_ERR_NULL: i32 = 2;
/// A pointer not aligned to its type (8 bytes for `uint64_t`).
pub const RP_ERR_ALIGN: i32 = 3;
/// An array length that does not fit the unit (too few values, or not whole rows).
pub const RP_ERR_LENGTH: i32 = 4;
/// The call does not fit the handle's unit (e.g. `rp_rti` on a slab handle).
pub const RP_ERR_UNIT: i32 = 5;
/// An internal error (a bug in raypipe) caught at the boundary; the message says where.
pub const RP_ERR_INTERNAL: i32 = 6;

/// A unit handle: one model in one format with its options (opaque; immutable, so it may be
/// shared by threads).
pub struct RpUnit(unit::Unit);

/// A coverage recorder (opaque; rows may be added from several threads).
pub struct RpCover(cover::Recorder);

thread_local! {
    /// This thread's last error message.
    static LAST: RefCell<CString> = RefCell::new(CString::default());
}

struct Fail(i32, String);

fn set_last(msg: &str) {
    let c = CString::new(msg.replace('\0', " ")).unwrap_or_default();
    LAST.with(|l| *l.borrow_mut() = c);
}

/// Runs `f`, turning its error or a panic into a code and this thread's message.
fn guard(f: impl FnOnce() -> Result<(), Fail>) -> i32 {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => {
            set_last("");
            RP_OK
        }
        Ok(Err(Fail(code, msg))) => {
            set_last(&msg);
            code
        }
        Err(p) => {
            let what = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic".into());
            set_last(&format!("internal error: {what}"));
            RP_ERR_INTERNAL
        }
    }
}

fn arg(msg: String) -> Fail {
    Fail(RP_ERR_ARGUMENT, msg)
}

/// `p` as a string, or the error naming `what`.
///
/// # Safety
/// `p` is null or a NUL-terminated string.
unsafe fn text<'a>(p: *const c_char, what: &str) -> Result<&'a str, Fail> {
    if p.is_null() {
        return Err(Fail(RP_ERR_NULL, format!("{what} is a null pointer")));
    }
    // SAFETY: non-null and NUL-terminated (the caller's promise)
    unsafe { CStr::from_ptr(p) }.to_str().map_err(|_| arg(format!("{what} is not UTF-8")))
}

/// The handle behind `u`.
///
/// # Safety
/// `u` is null or a handle from [`rp_unit_new`] not yet freed.
unsafe fn handle<'a>(u: *const RpUnit) -> Result<&'a unit::Unit, Fail> {
    if u.is_null() {
        return Err(Fail(RP_ERR_NULL, "the unit handle is a null pointer".into()));
    }
    // SAFETY: a live handle (the caller's promise)
    Ok(unsafe { &(*u).0 })
}

/// `p` (naming `what`) is not null and aligned for `u64`.
fn check_ptr(p: *const u64, what: &str) -> Result<(), Fail> {
    if p.is_null() {
        return Err(Fail(RP_ERR_NULL, format!("{what} is a null pointer")));
    }
    if !(p as usize).is_multiple_of(std::mem::align_of::<u64>()) {
        return Err(Fail(RP_ERR_ALIGN, format!("{what} is not aligned to 8 bytes")));
    }
    Ok(())
}

/// `n` values at `p`, checked for null and alignment.
///
/// # Safety
/// `p` is null or points to `n` readable `uint64_t`.
unsafe fn slice<'a>(p: *const u64, n: usize, what: &str) -> Result<&'a [u64], Fail> {
    check_ptr(p, what)?;
    // SAFETY: non-null, aligned, n values (the caller's promise)
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// [`slice`] for writing.
///
/// # Safety
/// `p` is null or points to `n` writable `uint64_t` not otherwise borrowed.
unsafe fn slice_mut<'a>(p: *mut u64, n: usize, what: &str) -> Result<&'a mut [u64], Fail> {
    check_ptr(p, what)?;
    // SAFETY: non-null, aligned, n values, exclusive (the caller's promise)
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

/// The body of the `*_new` calls that take a unit, a format and options: the strings read
/// (options null: none), `make` run on them, its result boxed into `*out`.
///
/// # Safety
/// As [`rp_unit_new`].
unsafe fn create<T>(
    unit: *const c_char,
    format: *const c_char,
    options: *const c_char,
    out: *mut *mut T,
    make: impl FnOnce(&str, &str, &str) -> Result<T, String>,
) -> i32 {
    guard(|| {
        if out.is_null() {
            return Err(Fail(RP_ERR_NULL, "out is a null pointer".into()));
        }
        // SAFETY: the caller's promise (null is checked)
        let (u, f) = unsafe { (text(unit, "unit")?, text(format, "format")?) };
        let o = if options.is_null() { "" } else { unsafe { text(options, "options")? } };
        let x = make(u, f, o).map_err(arg)?;
        // SAFETY: out is non-null and writable (the caller's promise)
        unsafe { *out = Box::into_raw(Box::new(x)) };
        Ok(())
    })
}

/// raypipe's version, a NUL-terminated string (static).
#[no_mangle]
pub extern "C" fn rp_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// This thread's last error message ("" after a call that succeeded), NUL-terminated; valid
/// until this thread's next raypipe call.
#[no_mangle]
pub extern "C" fn rp_last_error() -> *const c_char {
    LAST.with(|l| l.borrow().as_ptr())
}

/// Creates a unit handle into `*out`: `unit` is `rti`, `slab` or `op`; `format` a format name
/// as the CLI takes it (`f32`, `fp16:ftz`, `e8m16`, `q8.24:divide`, …); `options` the unit's
/// CLI flags separated by spaces (rti: `--cull`, `--det-threshold X`, `--tie first|last`;
/// slab: `--variant plain|conservative|directed|take-on-false|embree`), or null for none.
/// Free it with [`rp_unit_free`].
///
/// # Safety
/// `unit` and `format` are NUL-terminated strings, `options` one or null, `out` a writable
/// pointer (each may be null: that is an error code, not a crash).
#[no_mangle]
pub unsafe extern "C" fn rp_unit_new(
    unit: *const c_char,
    format: *const c_char,
    options: *const c_char,
    out: *mut *mut RpUnit,
) -> i32 {
    // SAFETY: the caller's promise (as this function's)
    unsafe { create(unit, format, options, out, |u, f, o| unit::Unit::new(u, f, o).map(RpUnit)) }
}

/// Creates a traverse unit handle into `*out` from the vector set in directory `set_dir`
/// (written by `raypipe vectors --unit traverse`): the tree is read from the set's BRAM images
/// (every file checked against the manifest's sha256, every address word against the next
/// level), with the set's format, slab variant and N. Its rows: inputs ox oy oz dx dy dz tmin
/// tmax (8), outputs the set's `traverse_expected.hex` row (count, N leaf ids, passes, box
/// tests, each level's 2-bit history state); no stage signals. Free it with [`rp_unit_free`].
///
/// # Safety
/// `set_dir` a NUL-terminated string (or null: an error code), `out` writable (or null).
#[no_mangle]
pub unsafe extern "C" fn rp_traverse_open(set_dir: *const c_char, out: *mut *mut RpUnit) -> i32 {
    guard(|| {
        if out.is_null() {
            return Err(Fail(RP_ERR_NULL, "out is a null pointer".into()));
        }
        let d = unsafe { text(set_dir, "set_dir")? };
        let h = unit::Unit::open_set(std::path::Path::new(d)).map_err(arg)?;
        // SAFETY: out is non-null and writable (the caller's promise)
        unsafe { *out = Box::into_raw(Box::new(RpUnit(h))) };
        Ok(())
    })
}

/// Frees a handle from [`rp_unit_new`] (null: nothing happens).
///
/// # Safety
/// `u` is null or a handle not yet freed; it is not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn rp_unit_free(u: *mut RpUnit) {
    if !u.is_null() {
        // SAFETY: a handle from rp_unit_new (the caller's promise)
        drop(unsafe { Box::from_raw(u) });
    }
}

/// Values in one input row of the unit (rti 17, slab 14, op 3, traverse 8); 0 for a null handle.
///
/// # Safety
/// `u` is null or a live handle.
#[no_mangle]
pub unsafe extern "C" fn rp_unit_inputs(u: *const RpUnit) -> usize {
    unsafe { handle(u) }.map_or(0, |h| h.kind.inputs())
}

/// Values in one output row of the unit (rti 5: valid, hit, t, u, v; slab 3: hit, t_near,
/// t_far; op 2: result, cmp; traverse: the set's expected row); 0 for a null handle.
///
/// # Safety
/// `u` is null or a live handle.
#[no_mangle]
pub unsafe extern "C" fn rp_unit_outputs(u: *const RpUnit) -> usize {
    unsafe { handle(u) }.map_or(0, |h| h.outputs())
}

/// Stage signals in one stage row of the unit (0 for op, for the directed slab variant, whose
/// signal set depends on the data, and for a null handle).
///
/// # Safety
/// `u` is null or a live handle.
#[no_mangle]
pub unsafe extern "C" fn rp_unit_stages(u: *const RpUnit) -> usize {
    unsafe { handle(u) }.map_or(0, |h| h.stage_names.len())
}

/// The name of stage signal `i` (as the manifest names it), NUL-terminated and owned by the
/// handle; null when `i` is out of range or the handle is null.
///
/// # Safety
/// `u` is null or a live handle; the string lives as long as the handle.
#[no_mangle]
pub unsafe extern "C" fn rp_unit_stage_name(u: *const RpUnit, i: usize) -> *const c_char {
    match unsafe { handle(u) } {
        Ok(h) => h.stage_cnames.get(i).map_or(std::ptr::null(), |c| c.as_ptr()),
        Err(_) => std::ptr::null(),
    }
}

/// Bits of one encoding of the handle's format (0 for a null handle).
///
/// # Safety
/// `u` is null or a live handle.
#[no_mangle]
pub unsafe extern "C" fn rp_unit_width(u: *const RpUnit) -> u32 {
    unsafe { handle(u) }.map_or(0, |h| h.width)
}

/// The bits of output `i` of a row (1 for a flag, the format's width for a value); 0 when `i`
/// is out of range or the handle is null.
///
/// # Safety
/// `u` is null or a live handle.
#[no_mangle]
pub unsafe extern "C" fn rp_unit_output_width(u: *const RpUnit, i: usize) -> u32 {
    unsafe { handle(u) }.ok().and_then(|h| h.output_width(i)).unwrap_or(0)
}

/// The bits of stage signal `i` (1 for a flag, the format's width for a register); 0 when `i`
/// is out of range or the handle is null.
///
/// # Safety
/// `u` is null or a live handle.
#[no_mangle]
pub unsafe extern "C" fn rp_unit_stage_width(u: *const RpUnit, i: usize) -> u32 {
    unsafe { handle(u) }.ok().and_then(|h| h.stage_widths.get(i).copied()).unwrap_or(0)
}

/// `*bits` = the format's encoding of `x`, rounded as the format's conversion from binary64
/// rounds (the rounding of `raypipe vectors`' inputs: to nearest, ties to even, for floats).
///
/// # Safety
/// `u` null or a live handle, `bits` null or writable.
#[no_mangle]
pub unsafe extern "C" fn rp_encode(u: *const RpUnit, x: f64, bits: *mut u64) -> i32 {
    guard(|| {
        let h = unsafe { handle(u)? };
        if bits.is_null() {
            return Err(Fail(RP_ERR_NULL, "bits is a null pointer".into()));
        }
        // SAFETY: non-null and writable (the caller's promise)
        unsafe { *bits = h.encode(x) };
        Ok(())
    })
}

/// `*x` = the value of encoding `bits` in binary64 (exact for every format of at most 53
/// significant bits; NaN for a NaN encoding).
///
/// # Safety
/// `u` null or a live handle, `x` null or writable.
#[no_mangle]
pub unsafe extern "C" fn rp_decode(u: *const RpUnit, bits: u64, x: *mut f64) -> i32 {
    guard(|| {
        let h = unsafe { handle(u)? };
        if x.is_null() {
            return Err(Fail(RP_ERR_NULL, "x is a null pointer".into()));
        }
        let value = h.decode(bits).map_err(arg)?;
        // SAFETY: non-null and writable (the caller's promise)
        unsafe { *x = value };
        Ok(())
    })
}

/// One test: `inputs` (`n_inputs` = [`rp_unit_inputs`] values) → `outputs` (`n_outputs` ≥
/// [`rp_unit_outputs`]); when `stages` is not null and `n_stages` is not 0, every stage signal
/// into it (`n_stages` ≥ [`rp_unit_stages`]; a DPI caller, whose array is never null, passes
/// 0 for none).
///
/// # Safety
/// Each pointer is null or points to as many `uint64_t` as its length says (`outputs` and
/// `stages` writable, none overlapping another).
#[no_mangle]
pub unsafe extern "C" fn rp_eval(
    u: *const RpUnit,
    inputs: *const u64,
    n_inputs: usize,
    outputs: *mut u64,
    n_outputs: usize,
    stages: *mut u64,
    n_stages: usize,
) -> i32 {
    let stages = if n_stages == 0 { std::ptr::null_mut() } else { stages };
    guard(|| unsafe { eval(u, None, inputs, n_inputs, outputs, n_outputs, stages, n_stages) })
}

/// The shared body of the one-test calls (`want`: the unit the call is for).
///
/// # Safety
/// As [`rp_eval`].
#[allow(clippy::too_many_arguments)]
unsafe fn eval(
    u: *const RpUnit,
    want: Option<unit::Kind>,
    inputs: *const u64,
    n_inputs: usize,
    outputs: *mut u64,
    n_outputs: usize,
    stages: *mut u64,
    n_stages: usize,
) -> Result<(), Fail> {
    let h = unsafe { handle(u)? };
    if let Some(k) = want {
        if k != h.kind {
            return Err(Fail(RP_ERR_UNIT, format!("a {:?} call on a {:?} unit", k, h.kind)));
        }
    }
    let (ni, no, ns) = (h.kind.inputs(), h.outputs(), h.stage_names.len());
    if n_inputs != ni {
        return Err(Fail(RP_ERR_LENGTH, format!("{n_inputs} inputs for a {:?} unit, which takes {ni}", h.kind)));
    }
    if n_outputs < no {
        return Err(Fail(RP_ERR_LENGTH, format!("room for {n_outputs} outputs, the {:?} unit gives {no}", h.kind)));
    }
    if !stages.is_null() && n_stages < ns {
        return Err(Fail(RP_ERR_LENGTH, format!("room for {n_stages} stage signals, the unit has {ns}")));
    }
    let row = unsafe { slice(inputs, ni, "inputs")? };
    let out = unsafe { slice_mut(outputs, no, "outputs")? };
    if !stages.is_null() && !h.has_stages {
        return Err(Fail(
            RP_ERR_UNIT,
            "the directed slab variant's signal set depends on the data: no stage signals (pass a null stages pointer)"
                .into(),
        ));
    }
    if stages.is_null() {
        return h.eval(row, out, None).map_err(arg);
    }
    let st = unsafe { slice_mut(stages, ns, "stages")? };
    let mut v = Vec::with_capacity(ns);
    h.eval(row, out, Some(&mut v)).map_err(arg)?;
    if v.len() != ns {
        return Err(Fail(RP_ERR_INTERNAL, format!("internal error: {} stage signals, {ns} named", v.len())));
    }
    st.copy_from_slice(&v);
    Ok(())
}

/// One RTI test ([`rp_eval`] on an rti handle): inputs ox oy oz dx dy dz tmin tmax v0x v0y
/// v0z v1x v1y v1z v2x v2y v2z (17), outputs valid hit t u v (5), stages optional.
///
/// # Safety
/// As [`rp_eval`].
#[no_mangle]
pub unsafe extern "C" fn rp_rti(u: *const RpUnit, inputs: *const u64, outputs: *mut u64, stages: *mut u64) -> i32 {
    guard(|| unsafe { eval(u, Some(unit::Kind::Rti), inputs, 17, outputs, 5, stages, usize::MAX) })
}

/// One slab test ([`rp_eval`] on a slab handle, any variant): inputs ox oy oz dx dy dz tmin
/// tmax minx miny minz maxx maxy maxz (14), outputs hit t_near t_far (3), stages optional.
///
/// # Safety
/// As [`rp_eval`].
#[no_mangle]
pub unsafe extern "C" fn rp_slab(u: *const RpUnit, inputs: *const u64, outputs: *mut u64, stages: *mut u64) -> i32 {
    guard(|| unsafe { eval(u, Some(unit::Kind::Slab), inputs, 14, outputs, 3, stages, usize::MAX) })
}

/// One operation ([`rp_eval`] on an op handle): `op` 0 add, 1 sub, 2 mul, 3 div (the format's
/// division mode), 4 lt, 5 le on encodings `a`, `b`; `*result` the result's encoding (0 for
/// a comparison), `*cmp` the comparison's bit (0 for arithmetic).
///
/// # Safety
/// `u` null or a live op handle; `result` and `cmp` null or writable.
#[no_mangle]
pub unsafe extern "C" fn rp_op(u: *const RpUnit, op: u64, a: u64, b: u64, result: *mut u64, cmp: *mut u64) -> i32 {
    guard(|| {
        if result.is_null() || cmp.is_null() {
            return Err(Fail(RP_ERR_NULL, "result or cmp is a null pointer".into()));
        }
        let mut out = [0u64; 2];
        unsafe { eval(u, Some(unit::Kind::Op), [op, a, b].as_ptr(), 3, out.as_mut_ptr(), 2, std::ptr::null_mut(), 0)? };
        // SAFETY: non-null and writable (the caller's promise)
        unsafe {
            *result = out[0];
            *cmp = out[1];
        }
        Ok(())
    })
}

/// `count` tests at once: `inputs` holds `count` input rows, `outputs` room for `count` output
/// rows (row-major, `n_inputs` = count × [`rp_unit_inputs`], `n_outputs` ≥ count ×
/// [`rp_unit_outputs`]), on the SIMD kernels where the format has them (the same bits as
/// [`rp_eval`]); every row is checked before any is evaluated.
///
/// # Safety
/// `inputs` points to `n_inputs` values, `outputs` to `n_outputs` writable ones (or null).
#[no_mangle]
pub unsafe extern "C" fn rp_eval_batch(
    u: *const RpUnit,
    count: usize,
    inputs: *const u64,
    n_inputs: usize,
    outputs: *mut u64,
    n_outputs: usize,
) -> i32 {
    guard(|| {
        let h = unsafe { handle(u)? };
        let (ni, no) = (h.kind.inputs(), h.outputs());
        let (want_in, want_out) = match (count.checked_mul(ni), count.checked_mul(no)) {
            (Some(a), Some(b)) => (a, b),
            _ => return Err(Fail(RP_ERR_LENGTH, format!("count {count} is too large"))),
        };
        if n_inputs != want_in || n_outputs < want_out {
            return Err(Fail(
                RP_ERR_LENGTH,
                format!(
                    "{count} rows of a {:?} unit take {want_in} inputs and {want_out} outputs; got {n_inputs} and room for {n_outputs}",
                    h.kind
                ),
            ));
        }
        if count == 0 {
            return Ok(());
        }
        let input = unsafe { slice(inputs, want_in, "inputs")? };
        let out = unsafe { slice_mut(outputs, want_out, "outputs")? };
        h.batch(input, out).map_err(arg)
    })
}

/// Creates a coverage recorder into `*out` for the unit `unit` ("rti", "slab" or "op") in
/// `format` with `options` (as [`rp_unit_new`]; the directed slab variant has no coverage
/// model): [`rp_cover_add`] counts each row a testbench drives into its DUT, [`rp_cover_write`]
/// writes the coverage file `raypipe cover` reads and merges (docs/coverage.md). Free it with
/// [`rp_cover_free`].
///
/// # Safety
/// As [`rp_unit_new`].
#[no_mangle]
pub unsafe extern "C" fn rp_cover_new(
    unit: *const c_char,
    format: *const c_char,
    options: *const c_char,
    out: *mut *mut RpCover,
) -> i32 {
    // SAFETY: the caller's promise (as rp_unit_new's)
    unsafe { create(unit, format, options, out, |u, f, o| cover::Recorder::new(u, f, o).map(RpCover)) }
}

/// Counts one input row (`n_inputs` = the unit's [`rp_unit_inputs`] values, the row as
/// [`rp_eval`] takes it) into the recorder.
///
/// # Safety
/// `c` is null or a recorder not yet freed; `inputs` null or `n_inputs` readable values.
#[no_mangle]
pub unsafe extern "C" fn rp_cover_add(c: *const RpCover, inputs: *const u64, n_inputs: usize) -> i32 {
    guard(|| {
        if c.is_null() {
            return Err(Fail(RP_ERR_NULL, "the recorder is a null pointer".into()));
        }
        // SAFETY: a live recorder; n_inputs readable values (the caller's promise)
        let r = unsafe { &(*c).0 };
        if n_inputs != r.inputs() {
            return Err(Fail(RP_ERR_LENGTH, format!("{n_inputs} inputs for a unit that takes {}", r.inputs())));
        }
        let row = unsafe { slice(inputs, n_inputs, "inputs")? };
        r.add(row).map_err(arg)
    })
}

/// Rows the recorder counted (0 for a null pointer).
///
/// # Safety
/// `c` is null or a recorder not yet freed.
#[no_mangle]
pub unsafe extern "C" fn rp_cover_rows(c: *const RpCover) -> u64 {
    if c.is_null() {
        return 0;
    }
    // SAFETY: a live recorder (the caller's promise)
    unsafe { &(*c).0 }.rows()
}

/// Writes the recorder's coverage to the file `path` (atomically; a file there that raypipe
/// did not write is never replaced: `RP_ERR_ARGUMENT`). May be called again (the counts so far).
///
/// # Safety
/// `c` is null or a recorder not yet freed; `path` a NUL-terminated string or null.
#[no_mangle]
pub unsafe extern "C" fn rp_cover_write(c: *const RpCover, path: *const c_char) -> i32 {
    guard(|| {
        if c.is_null() {
            return Err(Fail(RP_ERR_NULL, "the recorder is a null pointer".into()));
        }
        // SAFETY: the caller's promise
        let (r, p) = unsafe { (&(*c).0, text(path, "path")?) };
        r.write(std::path::Path::new(p)).map_err(arg)
    })
}

/// Frees a recorder (null: nothing happens); its counts are lost unless written first.
///
/// # Safety
/// `c` is null or a recorder not yet freed; it is not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn rp_cover_free(c: *mut RpCover) {
    if !c.is_null() {
        // SAFETY: a recorder from rp_cover_new (the caller's promise)
        drop(unsafe { Box::from_raw(c) });
    }
}
