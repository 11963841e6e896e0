//! raypipe's models for Python (`import raypipe`): unit handles with numpy batch calls (the
//! SIMD kernels, the GIL released), single tests as dicts with every stage signal, the format
//! parser and the vector-set reader. The arithmetic is the C ABI's (`raypipe_capi::unit`).

use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyIOError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use raypipe_capi::unit::{Kind, Unit as CUnit};

/// One unit (rti, slab or op) in one format with its options, as the CLI names them.
#[pyclass(frozen, module = "raypipe._raypipe")]
struct Unit {
    u: CUnit,
    input_names: Vec<&'static str>,
}

const RTI_IN: [&str; 17] =
    ["ox", "oy", "oz", "dx", "dy", "dz", "tmin", "tmax", "v0x", "v0y", "v0z", "v1x", "v1y", "v1z", "v2x", "v2y", "v2z"];
impl Unit {
    fn of(u: CUnit) -> Self {
        let input_names = match u.kind {
            Kind::Rti => RTI_IN.to_vec(),
            Kind::Slab => SLAB_IN.to_vec(),
            Kind::Op => vec!["op", "a", "b"],
            Kind::Traverse => RTI_IN[..8].to_vec(),
        };
        Unit { u, input_names }
    }
}

const SLAB_IN: [&str; 14] =
    ["ox", "oy", "oz", "dx", "dy", "dz", "tmin", "tmax", "minx", "miny", "minz", "maxx", "maxy", "maxz"];

#[pymethods]
impl Unit {
    /// `Unit("rti", "e8m16:ftz", "--cull")`; options: rti `--cull`, `--det-threshold X`,
    /// `--tie first|last`; slab `--variant V`. A bad name or option raises ValueError.
    #[new]
    #[pyo3(signature = (unit, format, options = ""))]
    fn new(unit: &str, format: &str, options: &str) -> PyResult<Self> {
        Ok(Unit::of(CUnit::new(unit, format, options).map_err(PyValueError::new_err)?))
    }

    /// The traverse unit of a vector set written by `raypipe vectors --unit traverse`: the
    /// tree read from its BRAM images (checked against the manifest), its format, variant and
    /// N. Rows: inputs ox … tmax, outputs the set's `traverse_expected.hex` fields.
    #[staticmethod]
    fn traverse(set_dir: std::path::PathBuf) -> PyResult<Self> {
        Ok(Unit::of(CUnit::open_set(&set_dir).map_err(PyValueError::new_err)?))
    }

    /// The format's canonical name.
    #[getter]
    fn format(&self) -> String {
        self.u.format.clone()
    }
    /// Bits of one encoding.
    #[getter]
    fn width(&self) -> u32 {
        self.u.width
    }
    /// The input row's field names, in order.
    #[getter]
    fn inputs(&self) -> Vec<&'static str> {
        self.input_names.clone()
    }
    /// The output row's field names, in order.
    #[getter]
    fn outputs(&self) -> Vec<String> {
        self.u.output_names.clone()
    }
    /// The stage signals' names, in the order of the vector set's stage file.
    #[getter]
    fn stage_names(&self) -> Vec<String> {
        self.u.stage_names.clone()
    }

    /// One test: an input row (encodings) to a dict of the outputs, and, with `stages=True`,
    /// `"stages"`: a dict of every stage signal in pipeline order.
    #[pyo3(signature = (row, stages = false))]
    fn eval<'py>(&self, py: Python<'py>, row: Vec<u64>, stages: bool) -> PyResult<Bound<'py, PyDict>> {
        let mut out = vec![0u64; self.u.outputs()];
        let mut st = Vec::new();
        let want = stages && self.u.has_stages;
        if stages && !self.u.has_stages {
            return Err(PyValueError::new_err(
                "the directed slab variant's signal set depends on the data: no stage signals",
            ));
        }
        self.u.eval(&row, &mut out, want.then_some(&mut st)).map_err(PyValueError::new_err)?;
        let d = PyDict::new(py);
        for (name, v) in self.u.output_names.iter().zip(&out) {
            d.set_item(name, v)?;
        }
        if want {
            let s = PyDict::new(py);
            for (name, v) in self.u.stage_names.iter().zip(&st) {
                s.set_item(name, v)?;
            }
            d.set_item("stages", s)?;
        }
        Ok(d)
    }

    /// Many tests: a (n, inputs) uint64 array of encodings to a (n, outputs) uint64 array, on
    /// the SIMD kernels where the format has them (the GIL is released meanwhile).
    fn eval_batch<'py>(
        &self,
        py: Python<'py>,
        rows: PyReadonlyArray2<'py, u64>,
    ) -> PyResult<Bound<'py, PyArray2<u64>>> {
        let (n, ni, no) = (rows.shape()[0], rows.shape()[1], self.u.outputs());
        if ni != self.u.kind.inputs() {
            return Err(PyValueError::new_err(format!(
                "rows have {ni} columns; the {:?} unit takes {}",
                self.u.kind,
                self.u.kind.inputs()
            )));
        }
        let out = PyArray2::<u64>::zeros(py, [n, no], false);
        {
            // the rows in place when C-contiguous, else a contiguous copy
            let copy;
            // (as_slice also accepts a Fortran-ordered array, whose memory order is not the
            // rows' order: only a C-contiguous one is read in place)
            let input: &[u64] = match rows.as_slice() {
                Ok(s) if rows.is_c_contiguous() => s,
                _ => {
                    copy = rows.as_array().iter().copied().collect::<Vec<u64>>();
                    &copy
                }
            };
            let mut w = out.readwrite();
            let dst = w.as_slice_mut().expect("a new array is contiguous");
            let u = &self.u;
            py.allow_threads(|| u.batch(input, dst)).map_err(PyValueError::new_err)?;
        }
        Ok(out)
    }

    /// Many f32 RTI tests from columns: a (17, n) float32 array (C-contiguous: read in place; one row per
    /// input, in the order of `inputs`) to a dict of output columns (`valid`, `hit`: bool;
    /// `t`, `u`, `v`: float32), run through the binary32 kernels in L1-sized chunks with the
    /// GIL released: the columnar layout the kernels read, with no per-row conversion.
    /// `out`: a dict of those five arrays (length n) to write into, reused across calls.
    #[pyo3(signature = (cols, out = None))]
    fn eval_columns<'py>(
        &self,
        py: Python<'py>,
        cols: PyReadonlyArray2<'py, f32>,
        out: Option<Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        if cols.shape()[0] != 17 {
            return Err(PyValueError::new_err(format!("{} columns; the rti unit takes 17", cols.shape()[0])));
        }
        let n = cols.shape()[1];
        // in place when C-contiguous, else a copy in the logical order (as_slice would also
        // accept a Fortran-ordered array, in the wrong order)
        let copy;
        let src: &[f32] = match cols.as_slice() {
            Ok(s) if cols.is_c_contiguous() => s,
            _ => {
                copy = cols.as_array().iter().copied().collect::<Vec<f32>>();
                &copy
            }
        };
        // the output columns: the caller's (`out`, reused across calls: no fresh pages to
        // fault in), or new ones
        let (valid, hit) = (out_column::<bool>(py, &out, "valid", n)?, out_column::<bool>(py, &out, "hit", n)?);
        let t = out_column::<f32>(py, &out, "t", n)?;
        let (u, v) = (out_column::<f32>(py, &out, "u", n)?, out_column::<f32>(py, &out, "v", n)?);
        {
            let (mut wv, mut wh, mut wt, mut wu, mut ww) =
                (valid.readwrite(), hit.readwrite(), t.readwrite(), u.readwrite(), v.readwrite());
            let contiguous = |_| PyValueError::new_err("the out arrays must be contiguous");
            let (ov, oh, ot, ou, ow) = (
                wv.as_slice_mut().map_err(contiguous)?,
                wh.as_slice_mut().map_err(contiguous)?,
                wt.as_slice_mut().map_err(contiguous)?,
                wu.as_slice_mut().map_err(contiguous)?,
                ww.as_slice_mut().map_err(contiguous)?,
            );
            let m = &self.u;
            py.allow_threads(|| m.rti_columns_f32(src, ov, oh, ot, ou, ow)).map_err(PyValueError::new_err)?;
        }
        let d = PyDict::new(py);
        d.set_item("valid", valid)?;
        d.set_item("hit", hit)?;
        d.set_item("t", t)?;
        d.set_item("u", u)?;
        d.set_item("v", v)?;
        Ok(d)
    }

    /// The format's encoding of `x` (its conversion's rounding: to nearest, ties to even).
    fn encode(&self, x: f64) -> u64 {
        self.u.encode(x)
    }

    /// The value of an encoding.
    fn decode(&self, bits: u64) -> PyResult<f64> {
        self.u.decode(bits).map_err(PyValueError::new_err)
    }

    fn __repr__(&self) -> String {
        format!("raypipe.Unit({:?}, {:?})", format!("{:?}", self.u.kind).to_lowercase(), self.u.format)
    }
}

/// The output column `name` of length `n`: the caller's array in `out` (checked: its type
/// and length), or a new one.
fn out_column<'py, T: numpy::Element>(
    py: Python<'py>,
    out: &Option<Bound<'py, PyDict>>,
    name: &str,
    n: usize,
) -> PyResult<Bound<'py, PyArray1<T>>> {
    let given = match out {
        Some(d) => d.get_item(name)?,
        None => None,
    };
    let Some(a) = given else { return Ok(PyArray1::<T>::zeros(py, n, false)) };
    let what = if std::any::type_name::<T>() == "bool" { "a bool" } else { "a float32" };
    let a = a
        .downcast_into::<PyArray1<T>>()
        .map_err(|_| PyValueError::new_err(format!("out[{name:?}] must be {what} array")))?;
    match a.len() == n {
        true => Ok(a),
        false => Err(PyValueError::new_err(format!("out[{name:?}] has {} values, not {n}", a.len()))),
    }
}

/// A format name parsed: `{"name", "width", "kind": "float" | "fixed", "exp_bits" and
/// "man_bits" | "int_bits" and "frac_bits", "contract": {...}}`; ValueError if bad.
#[pyfunction]
fn parse_format<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyDict>> {
    use datapath::Format;
    let any: datapath::AnyFormat = name.parse().map_err(|e: String| PyValueError::new_err(e))?;
    let d = PyDict::new(py);
    let (name, width, kind, contract) =
        datapath::with_format!(&any, |f| (f.name(), f.width(), f.kind(), vectors::gen::contract_map(f)));
    d.set_item("name", name)?;
    d.set_item("width", width)?;
    match kind {
        datapath::format::FormatKind::Float(l) => {
            d.set_item("kind", "float")?;
            d.set_item("exp_bits", l.exp_bits)?;
            d.set_item("man_bits", l.man_bits)?;
        }
        datapath::format::FormatKind::Fixed { int_bits, frac_bits } => {
            d.set_item("kind", "fixed")?;
            d.set_item("int_bits", int_bits)?;
            d.set_item("frac_bits", frac_bits)?;
        }
    }
    let cd = PyDict::new(py);
    for (k, v) in contract {
        cd.set_item(k, v)?;
    }
    d.set_item("contract", cd)?;
    Ok(d)
}

/// A vector set written by `raypipe vectors`: `{"manifest": dict, "files": {name: (rows,
/// fields) uint64 array}}`, every file checked against the manifest's sha256.
#[pyfunction]
fn read_set<'py>(py: Python<'py>, dir: std::path::PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let text = std::fs::read_to_string(dir.join("manifest.json"))
        .map_err(|e| PyIOError::new_err(format!("{}: {e}", dir.join("manifest.json").display())))?;
    let m: vectors::manifest::Manifest =
        serde_json::from_str(&text).map_err(|e| PyValueError::new_err(format!("manifest.json: {e}")))?;
    let files = vectors::read::read_files(&dir, &m).map_err(PyValueError::new_err)?;
    let json = py.import("json")?;
    let d = PyDict::new(py);
    d.set_item("manifest", json.call_method1("loads", (text,))?)?;
    let fd = PyDict::new(py);
    for (fm, rows) in m.files.iter().zip(files) {
        let cols = fm.fields.len();
        let flat: Vec<u64> = rows.iter().flatten().copied().collect();
        let arr = numpy::PyArray1::from_vec(py, flat).reshape([rows.len(), cols])?;
        fd.set_item(&fm.name, arr)?;
    }
    d.set_item("files", fd)?;
    Ok(d)
}

/// A functional-coverage recorder of one unit (rti, slab or op), format and options: each row a
/// testbench drives into its DUT counted into the unit's coverage model (docs/coverage.md), then
/// written as a coverage file `raypipe cover` reports and merges. Rows may be added from
/// several threads.
#[pyclass(frozen, module = "raypipe._raypipe")]
struct Cover(raypipe_capi::cover::Recorder);

#[pymethods]
impl Cover {
    /// `Cover("slab", "fp16", "--variant conservative")`: names and options as `Unit` takes
    /// them (the traverse unit and the directed slab variant have no coverage model:
    /// ValueError).
    #[new]
    #[pyo3(signature = (unit, format, options = ""))]
    fn new(unit: &str, format: &str, options: &str) -> PyResult<Self> {
        Ok(Cover(raypipe_capi::cover::Recorder::new(unit, format, options).map_err(PyValueError::new_err)?))
    }

    /// Counts one input row (as `Unit.eval` takes it: encodings, no class column); a bad row
    /// raises ValueError and is not counted.
    fn add(&self, row: Vec<u64>) -> PyResult<()> {
        self.0.add(&row).map_err(PyValueError::new_err)
    }

    /// Rows counted so far.
    #[getter]
    fn rows(&self) -> u64 {
        self.0.rows()
    }

    /// Writes the coverage file `path` (atomically; a file there raypipe did not write is never
    /// replaced: OSError).
    fn write(&self, path: std::path::PathBuf) -> PyResult<()> {
        self.0.write(&path).map_err(PyIOError::new_err)
    }
}

/// raypipe's version.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[pymodule]
fn _raypipe(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Unit>()?;
    m.add_class::<Cover>()?;
    m.add_function(wrap_pyfunction!(parse_format, m)?)?;
    m.add_function(wrap_pyfunction!(read_set, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    Ok(())
}
