//! # mpcontact._native
//!
//! The native half of the `mpcontact` Python package: the CLI's config
//! loader (`coordinator::config`), single solve (`coordinator::solve`),
//! kernels (`solver`) and sweep runner (`coordinator::run`, with the
//! `worker` crate's worker) made callable from Python. Only conversions live
//! here — Python values to config TOML, serde values and fields to Python
//! objects and numpy arrays, errors to exceptions — and the two things a
//! Python host needs: the GIL released during long calls, and Ctrl-C.
//! The public API and its docs are in `mpcontact/__init__.py`.

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::time::{Duration, Instant};

use coordinator::config::{heightmap_surface, Config};
use coordinator::solve::{solve_in_memory, CaseChoice};
use iceoryx2_bb_posix::signal::{FetchableSignal, SignalHandler};
use numpy::{Complex64, PyArray1, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

create_exception!(
    _native,
    SolveError,
    PyRuntimeError,
    "A case that was accepted but could not be solved (contact reaches the domain edge, gross sliding, not enough memory, …)."
);

/// An error of the config loader or of an argument: `ValueError` with the
/// whole context chain, as the CLI prints it after `error: `.
fn value_error(e: anyhow::Error) -> PyErr {
    PyValueError::new_err(format!("{e:#}"))
}

/// How often a long call lets Python run its signal handlers.
const SIGNAL_PERIOD: Duration = Duration::from_millis(50);

/// Runs `f` (which must not touch Python) with the GIL released and a tick
/// hook that every [`SIGNAL_PERIOD`] lets Python run its pending signal
/// handlers. A handler that raises (Ctrl-C → `KeyboardInterrupt`) cancels
/// the solve through `solver::cancel` — the solver's loops then return
/// `Cancelled` at their next iteration — and that exception is returned
/// instead of `f`'s error. The previous hook of the thread is restored.
fn interruptible<T: Send>(
    py: Python<'_>,
    f: impl FnOnce() -> anyhow::Result<T> + Send,
) -> Result<anyhow::Result<T>, PyErr> {
    let (outcome, raised) = py.detach(move || {
        let raised: Rc<RefCell<Option<PyErr>>> = Rc::new(RefCell::new(None));
        let seen = raised.clone();
        let mut last = Instant::now();
        let previous = solver::set_tick_hook(Some(Box::new(move || {
            if last.elapsed() < SIGNAL_PERIOD || seen.borrow().is_some() {
                return;
            }
            last = Instant::now();
            // Signal handlers run only on the main thread: elsewhere this is
            // a no-op, and the call cannot be interrupted.
            if let Err(e) = Python::attach(|py| py.check_signals()) {
                *seen.borrow_mut() = Some(e);
                solver::cancel();
            }
        })));
        let outcome = f();
        solver::set_tick_hook(previous);
        let raised = raised.borrow_mut().take();
        (outcome, raised)
    });
    match raised {
        Some(e) => Err(e),
        None => Ok(outcome),
    }
}

/// A sweep config: the TOML of `docs/config.md`, loaded and checked by the
/// CLI's loader. `set` is the CLI's `--set KEY=VALUE`.
#[pyclass(module = "mpcontact", name = "Config")]
#[derive(Clone)]
struct PyConfig {
    /// The TOML text the config was parsed from.
    text: String,
    /// The file it was read from (relative paths start at its directory).
    path: Option<PathBuf>,
    /// `--set` overrides applied to `text`, in order.
    sets: Vec<String>,
    /// The checked config.
    config: Config,
}

impl PyConfig {
    fn parse(text: &str, path: Option<&Path>, sets: &[String]) -> anyhow::Result<Config> {
        match path {
            Some(p) => Config::parse_file(text, sets, p),
            None => Config::parse(text, sets),
        }
    }
}

#[pymethods]
impl PyConfig {
    /// Reads and checks a config file (same keys, checks and messages as
    /// `mpcontact run CONFIG`); raises `ValueError` naming the key.
    #[staticmethod]
    fn from_toml(path: PathBuf) -> PyResult<Self> {
        let text = Config::read(&path).map_err(value_error)?;
        let config = Self::parse(&text, Some(&path), &[]).map_err(value_error)?;
        Ok(PyConfig {
            text,
            path: Some(path),
            sets: Vec::new(),
            config,
        })
    }

    /// Builds a config from a dict shaped like the TOML file (nested dicts
    /// for tables); relative height-map paths start at the current directory.
    #[staticmethod]
    fn from_dict(d: &Bound<'_, PyDict>) -> PyResult<Self> {
        let table = match to_toml(d.as_any(), "")? {
            toml::Value::Table(t) => t,
            _ => unreachable!("a dict converts to a table"),
        };
        let text = toml::to_string(&table)
            .map_err(|e| PyValueError::new_err(format!("cannot write the dict as TOML: {e}")))?;
        let config = Self::parse(&text, None, &[]).map_err(value_error)?;
        Ok(PyConfig {
            text,
            path: None,
            sets: Vec::new(),
            config,
        })
    }

    /// Overrides one key in place, as `--set KEY=VALUE` does (e.g.
    /// `cfg.set("grid.points", 256)`); the whole config is checked again and
    /// left unchanged when it raises `ValueError`.
    fn set(&mut self, key: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        if key.contains('=') {
            return Err(PyValueError::new_err(format!(
                "set: malformed key `{key}` (contains `=`)"
            )));
        }
        let value = to_toml(value, key)?;
        let mut sets = self.sets.clone();
        sets.push(format!("{key}={value}"));
        self.config = Self::parse(&self.text, self.path.as_deref(), &sets).map_err(value_error)?;
        self.sets = sets;
        Ok(())
    }

    /// Overrides several keys at once (a dict of key → value), checked
    /// together: a new `[surfaces.NAME]` table needs its keys in one go.
    fn set_many(&mut self, items: &Bound<'_, PyDict>) -> PyResult<()> {
        let mut sets = self.sets.clone();
        for (key, value) in items.iter() {
            let key: String = key.extract()?;
            if key.contains('=') {
                return Err(PyValueError::new_err(format!(
                    "set_many: malformed key `{key}` (contains `=`)"
                )));
            }
            let value = to_toml(&value, &key)?;
            sets.push(format!("{key}={value}"));
        }
        self.config = Self::parse(&self.text, self.path.as_deref(), &sets).map_err(value_error)?;
        self.sets = sets;
        Ok(())
    }

    /// A copy (later `set`s on either leave the other alone).
    fn copy(&self) -> Self {
        self.clone()
    }

    /// The effective config as TOML (what `run` echoes into summary.json).
    fn to_toml(&self) -> String {
        self.config.to_toml()
    }

    /// The `--set` overrides applied so far, as `KEY=VALUE` texts.
    #[getter]
    fn sets(&self) -> Vec<String> {
        self.sets.clone()
    }

    /// The sweep's cases in the CLI's order: `(material, surface,
    /// angle_deg)`, and `(material, surface, angle_deg, indenter)` in a
    /// sweep over balls (`sweep.indenters`).
    fn cases<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyTuple>>> {
        let cases = self.config.cases().map_err(value_error)?;
        cases
            .into_iter()
            .map(|(k, spec)| {
                let angle = spec.load.angle_deg;
                match k.indenter {
                    Some(ball) => (k.material, k.surface, angle, ball).into_pyobject(py),
                    None => (k.material, k.surface, angle).into_pyobject(py),
                }
            })
            .collect()
    }

    /// `sweep.indenters` (`None` without a ball axis).
    #[getter]
    fn indenters(&self) -> Option<Vec<String>> {
        self.config.sweep.indenters.clone()
    }

    /// `sweep.materials`.
    #[getter]
    fn materials(&self) -> Vec<String> {
        self.config.sweep.materials.clone()
    }

    /// `sweep.surfaces`.
    #[getter]
    fn surfaces(&self) -> Vec<String> {
        self.config.sweep.surfaces.clone()
    }

    /// The warnings `mpcontact check`, `solve` and `run` print for the
    /// patterns among `surfaces` (default: `sweep.surfaces`) whose pitch the
    /// grid does not resolve (below 2 cells per pitch).
    #[pyo3(signature = (surfaces=None))]
    fn unresolved_patterns(&self, surfaces: Option<Vec<String>>) -> PyResult<Vec<String>> {
        let surfaces = surfaces.unwrap_or_else(|| self.config.sweep.surfaces.clone());
        self.config
            .unresolved_patterns(&surfaces)
            .map_err(value_error)
    }

    /// `sweep.angles_deg`, expanded.
    #[getter]
    fn angles_deg(&self) -> PyResult<Vec<f64>> {
        self.config.sweep.angles_deg.values().map_err(value_error)
    }

    /// `grid.points` (N: the grid is N x N).
    #[getter]
    fn grid_points(&self) -> usize {
        self.config.grid.points
    }

    /// `grid.spacing_um` (cell size, µm).
    #[getter]
    fn spacing_um(&self) -> f64 {
        self.config.grid.spacing_um
    }

    fn __copy__(&self) -> Self {
        self.clone()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
        self.clone()
    }

    fn __repr__(&self) -> String {
        let from = match &self.path {
            Some(p) => format!("{:?}", p.display().to_string()),
            None => "dict".to_string(),
        };
        format!(
            "Config({from}, {} x {} cases, grid {}², sets={:?})",
            self.config.sweep.materials.len(),
            self.config.sweep.surfaces.len(),
            self.config.grid.points,
            self.sets
        )
    }
}

/// A Python value as TOML; `key` names it in errors (dotted path).
fn to_toml(v: &Bound<'_, PyAny>, key: &str) -> PyResult<toml::Value> {
    let sub = |k: &str| {
        if key.is_empty() {
            k.to_string()
        } else {
            format!("{key}.{k}")
        }
    };
    // bool before int: Python's True is an int too.
    if let Ok(b) = v.cast::<PyBool>() {
        return Ok(toml::Value::Boolean(b.is_true()));
    }
    if v.is_instance_of::<PyInt>() {
        return v.extract::<i64>().map(toml::Value::Integer).map_err(|_| {
            PyValueError::new_err(format!("{key}: integer out of range for a config"))
        });
    }
    if let Ok(f) = v.cast::<PyFloat>() {
        return Ok(toml::Value::Float(f.value()));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract::<String>()?));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, item) in d.iter() {
            let k: String = k.extract().map_err(|_| {
                let at = if key.is_empty() { "config" } else { key };
                PyTypeError::new_err(format!("{at}: table keys must be strings"))
            })?;
            let value = to_toml(&item, &sub(&k))?;
            t.insert(k, value);
        }
        return Ok(toml::Value::Table(t));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items = v
            .try_iter()?
            .enumerate()
            .map(|(i, item)| to_toml(&item?, &format!("{key}[{i}]")))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    // numpy scalars and arrays: integers through __index__, floats through
    // __float__, arrays through tolist().
    if v.hasattr("tolist")? && v.hasattr("ndim")? {
        let list = v.call_method0("tolist")?;
        if !list.is(v) {
            return to_toml(&list, key);
        }
    }
    if let Ok(i) = v.extract::<i64>() {
        return Ok(toml::Value::Integer(i));
    }
    if let Ok(f) = v.extract::<f64>() {
        return Ok(toml::Value::Float(f));
    }
    let what = v.get_type().name()?;
    Err(PyTypeError::new_err(format!(
        "{}: a {what} has no place in a config (numbers, strings, booleans, lists and dicts)",
        if key.is_empty() { "config" } else { key }
    )))
}

/// A serde value as Python objects (floats exact: serde_json keeps the f64).
fn to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value;
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => {
            if let Some(i) = n.as_i64() {
                i.into_pyobject(py)?.into_any()
            } else if let Some(u) = n.as_u64() {
                u.into_pyobject(py)?.into_any()
            } else {
                n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any()
            }
        }
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(to_py(py, item)?)?;
            }
            list.into_any()
        }
        Value::Object(map) => {
            let d = PyDict::new(py);
            for (k, item) in map {
                d.set_item(k, to_py(py, item)?)?;
            }
            d.into_any()
        }
    })
}

/// The surface argument of `solve`: a name, or heights in µm.
enum SurfaceArg {
    Named(Option<String>),
    Heights(Vec<f64>),
}

/// What `solve` returns: `case.json`, the fields, the stress arrays.
type SolveOutput<'py> = (
    Bound<'py, PyAny>,
    Bound<'py, PyDict>,
    Option<Bound<'py, PyDict>>,
);

/// Solves one case: `(scalars, fields, stress)` — `scalars` is the CLI's
/// `case.json` as a dict, `fields` the `.npy` fields as `(n, n)` arrays,
/// `stress` (with `[stress]`, else `None`) the arrays of `stress/*.npy`.
/// `heights` (µm, `(n, n)`, rows along y) replaces the named surface.
#[pyfunction]
#[pyo3(signature = (cfg, material=None, surface=None, heights=None, angle_deg=None, label="array", indenter=None))]
#[allow(clippy::too_many_arguments)]
fn solve<'py>(
    py: Python<'py>,
    cfg: &PyConfig,
    material: Option<String>,
    surface: Option<String>,
    heights: Option<PyReadonlyArray2<'py, f64>>,
    angle_deg: Option<f64>,
    label: &str,
    indenter: Option<String>,
) -> PyResult<SolveOutput<'py>> {
    let config = &cfg.config;
    let n = config.grid.points;
    let arg = match heights {
        None => SurfaceArg::Named(surface),
        Some(h) => {
            if surface.is_some() {
                return Err(PyValueError::new_err(
                    "give the surface either by name or as heights, not both",
                ));
            }
            let shape = h.shape();
            if shape != [n, n] {
                return Err(PyValueError::new_err(format!(
                    "surface: the height array has shape ({}, {}); the grid is {n} x {n} (grid.points)",
                    shape[0], shape[1]
                )));
            }
            // Logical C order whatever the strides: rows along y, as a file.
            SurfaceArg::Heights(h.as_array().iter().copied().collect())
        }
    };
    let case = match arg {
        SurfaceArg::Named(s) => {
            CaseChoice::new(config, material.as_deref(), s.as_deref(), angle_deg)
        }
        SurfaceArg::Heights(h) => {
            let surface = heightmap_surface(n, &h);
            surface.validate(n).map_err(|e| {
                PyValueError::new_err(format!("surface: invalid height array: {e}"))
            })?;
            CaseChoice::on_surface(config, material.as_deref(), label, surface, angle_deg)
        }
    }
    .and_then(|case| match &indenter {
        Some(name) => case.with_indenter(config, "indenter", name),
        None => Ok(case),
    })
    .map_err(value_error)?;
    // What the CLI prints on stderr, as Python warnings (stack level 2: the
    // caller of `mpcontact.solve`).
    let warn = |w: String| -> PyResult<()> {
        let text = std::ffi::CString::new(w).map_err(|e| PyValueError::new_err(e.to_string()))?;
        let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
        PyErr::warn(py, &category, &text, 2)
    };
    if let Some(w) = case.unresolved_pattern() {
        warn(w)?;
    }
    let solved = interruptible(py, move || {
        solve_in_memory(case, solver::Threads::available())
    })?
    .map_err(|e| SolveError::new_err(format!("{e:#}")))?;
    if let Some(w) = solved.beyond_hardness() {
        warn(w)?;
    }
    let value = serde_json::to_value(solved.case_json())
        .map_err(|e| PyRuntimeError::new_err(format!("case.json: {e}")))?;
    let scalars = to_py(py, &value)?;
    let fields = PyDict::new(py);
    let n = solved.fields.n;
    for (name, data) in solved.fields.present() {
        fields.set_item(name, PyArray1::from_slice(py, data).reshape([n, n])?)?;
    }
    // With a wear law: the worn depth at the saved cycles, named as the
    // CLI's files.
    for (cycle, data) in &solved.fields.wear_saved {
        fields.set_item(
            format!("wear_cycle_{cycle}"),
            PyArray1::from_slice(py, data).reshape([n, n])?,
        )?;
    }
    // With [stress]: the arrays of the CLI's stress/*.npy, by file stem.
    let stress = match &solved.stress {
        Some(so) => {
            let d = PyDict::new(py);
            for a in coordinator::output::stress::arrays(so) {
                d.set_item(
                    &a.name,
                    PyArray1::from_slice(py, &a.data).reshape([a.rows, a.cols])?,
                )?;
            }
            Some(d)
        }
        None => None,
    };
    Ok((scalars, fields, stress))
}

/// The surface compliance H(θ) of a material at each angle (degrees), 1/Pa:
/// complex `(m, 3, 3)`, what `mpcontact kernel` prints. `cfg` resolves the
/// names of its `[materials.*]` tables too.
#[pyfunction]
#[pyo3(signature = (material, angles_deg, cfg=None))]
fn kernel<'py>(
    py: Python<'py>,
    material: &str,
    angles_deg: Vec<f64>,
    cfg: Option<&PyConfig>,
) -> PyResult<Bound<'py, PyAny>> {
    let m = match cfg {
        Some(c) => c.config.material(material).map_err(value_error)?,
        None => solver::presets::material(material).ok_or_else(|| {
            PyValueError::new_err(format!(
                "material: unknown preset `{material}` (see mpcontact.materials(), or pass cfg= for [materials.*] tables)"
            ))
        })?,
    };
    if let Some(a) = angles_deg.iter().find(|a| !a.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "angles_deg: {a} is not a finite angle"
        )));
    }
    let mut data: Vec<Complex64> = Vec::with_capacity(angles_deg.len() * 9);
    for &deg in &angles_deg {
        let h = m.surface_compliance(deg.to_radians());
        data.extend(
            (0..3)
                .flat_map(|i| (0..3).map(move |j| (i, j)))
                .map(|ij| h[ij]),
        );
    }
    Ok(PyArray1::from_vec(py, data)
        .reshape([angles_deg.len(), 3, 3])?
        .into_any())
}

/// The preset material names (`mpcontact materials`).
#[pyfunction]
fn materials() -> Vec<String> {
    solver::presets::materials()
        .into_iter()
        .map(|m| m.name)
        .collect()
}

/// Runs a sweep as `mpcontact run` does — this process is the coordinator,
/// workers are started as `program [args…] worker --run RUN --index K` —
/// and returns summary.json's run part as a dict. Ctrl-C (or SIGTERM)
/// stops it with `KeyboardInterrupt`; `resume=True` continues. Messages
/// name the keywords (`resume=True`, `out=`), not the CLI's flags.
#[pyfunction]
#[pyo3(signature = (cfg, workers, out, resume, quiet, save_fields, program, args))]
#[allow(clippy::too_many_arguments)]
fn run<'py>(
    py: Python<'py>,
    cfg: &PyConfig,
    workers: usize,
    out: PathBuf,
    resume: bool,
    quiet: bool,
    save_fields: bool,
    program: PathBuf,
    args: Vec<String>,
) -> PyResult<Bound<'py, PyAny>> {
    if workers == 0 {
        return Err(PyValueError::new_err("workers must be at least 1"));
    }
    let run_args = coordinator::run::RunArgs {
        config: cfg.config.clone(),
        workers,
        out_dir: out,
        resume,
        quiet,
        save_fields,
        exe: coordinator::run::WorkerCommand {
            program,
            args,
            // Python finds its environment (a venv) from argv[0].
            arg0: None,
        },
        shard: None,
        names: coordinator::run::OptionNames::PYTHON,
    };
    let summary = py
        .detach(move || {
            let _saved = SavedSignals::save();
            // Ctrl-C and SIGTERM end the coordinator's wait loop, as in the
            // CLI: iceoryx2's handler catches them for the run (Python's
            // would only set a flag nobody reads while Rust waits), and a
            // signal left over from an earlier interrupted run is forgotten.
            let _catch = SignalHandler::register_multiple_signals(
                &vec![FetchableSignal::Interrupt, FetchableSignal::Terminate],
                &ignore_signal,
            );
            SignalHandler::last_signal();
            coordinator::run::run_sweep(&run_args)
        })
        .map_err(|e| {
            if e.downcast_ref::<coordinator::run::Interrupted>().is_some() {
                PyKeyboardInterrupt::new_err(format!("{e:#}"))
            } else {
                // Output directory, lock, memory, workers: the run, not a
                // case (a case that fails is a row with status `failed`).
                PyRuntimeError::new_err(format!("{e:#}"))
            }
        })?;
    let value = serde_json::to_value(&summary)
        .map_err(|e| PyRuntimeError::new_err(format!("summary: {e}")))?;
    to_py(py, &value)
}

/// The callback of the signals a sweep catches: iceoryx2's handler records
/// the signal, and the wait loop reads it.
fn ignore_signal(_: FetchableSignal) {}

/// The signal dispositions of this process, saved before a sweep and put
/// back after it. iceoryx2 installs its own handler for every non-fatal
/// signal the first time it is used (SIGINT, but also SIGTSTP, SIGPROF,
/// SIGUSR1, …): a CLI process ends soon after, a Python session goes on and
/// must get its Ctrl-C, Ctrl-Z and profilers back.
struct SavedSignals(Vec<(libc::c_int, libc::sigaction)>);

impl SavedSignals {
    fn save() -> Self {
        let mut saved = Vec::new();
        for sig in 1..32 {
            if sig == libc::SIGKILL || sig == libc::SIGSTOP {
                continue;
            }
            // SAFETY: sigaction with a null new action only reads the
            // current one into `old`, a plain C struct for which all-zero
            // is a valid value.
            let mut old: libc::sigaction = unsafe { std::mem::zeroed() };
            if unsafe { libc::sigaction(sig, std::ptr::null(), &mut old) } == 0 {
                saved.push((sig, old));
            }
        }
        SavedSignals(saved)
    }
}

impl Drop for SavedSignals {
    fn drop(&mut self) {
        for (sig, old) in &self.0 {
            // SAFETY: puts back a disposition that sigaction itself returned.
            unsafe { libc::sigaction(*sig, old, std::ptr::null_mut()) };
        }
    }
}

/// The worker process of a sweep (`mpcontact worker`), hosted by Python:
/// `worker::run_worker` with the CLI's case key. Returns the exit status
/// the worker process should end with (as `mpcontact worker` does): 0 when
/// the coordinator said it is done, `worker::EXIT_LEFT_WAITING` when it
/// looked gone while the worker waited (so the worker held no case).
#[pyfunction]
#[pyo3(name = "worker")]
fn serve_as_worker(py: Python<'_>, run: String, index: usize) -> PyResult<u8> {
    let end = py
        .detach(move || ::worker::run_worker::<coordinator::case::CaseKey>(&run, index))
        .map_err(|e| PyRuntimeError::new_err(format!("{e:#}")))?;
    Ok(match end {
        ::worker::WorkerEnd::Done => 0,
        ::worker::WorkerEnd::CoordinatorGone => ::worker::EXIT_LEFT_WAITING,
    })
}

/// Reads a scan the CLI reads (`.x3p`; `.npy` of µm with `pixel_um`):
/// `(heights, dx, dy)` — heights in m, `(ny, nx)`, rows along y, NaN where
/// missing; pixel sizes in m. The CLI's reader (`coordinator::scan_file`).
#[pyfunction]
#[pyo3(signature = (path, pixel_um=None))]
fn read_scan<'py>(
    py: Python<'py>,
    path: PathBuf,
    pixel_um: Option<[f64; 2]>,
) -> PyResult<(Bound<'py, PyAny>, f64, f64)> {
    let scan =
        coordinator::scan_file::read_scan(&path, pixel_um.map(|[x, y]| [x * 1e-6, y * 1e-6]))
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let h = PyArray1::from_slice(py, &scan.heights).reshape([scan.ny, scan.nx])?;
    Ok((h.into_any(), scan.dx, scan.dy))
}

/// Writes heights (m, `(ny, nx)`, rows along y, NaN where missing) on
/// pixels of `dx x dy` (m) as an `.x3p` the CLI reads, with f64 (`"D"`)
/// or f32 (`"F"`) heights.
#[pyfunction]
#[pyo3(signature = (path, heights, dx, dy, precision="D"))]
fn write_x3p(
    path: PathBuf,
    heights: PyReadonlyArray2<'_, f64>,
    dx: f64,
    dy: f64,
    precision: &str,
) -> PyResult<()> {
    use coordinator::scan_file::x3p::{self, DataType};
    let dtype = match precision {
        "D" => DataType::D,
        "F" => DataType::F,
        other => {
            return Err(PyValueError::new_err(format!(
                "precision: `{other}`: \"D\" (f64) or \"F\" (f32)"
            )))
        }
    };
    let shape = heights.shape();
    let (ny, nx) = (shape[0], shape[1]);
    let h: Vec<f64> = heights.as_array().iter().copied().collect();
    let scan = solver::Scan::new(nx, ny, dx, dy, h)
        .map_err(|e| PyValueError::new_err(format!("{}: {e}", path.display())))?;
    x3p::write(&path, &scan, dtype).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// The module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyConfig>()?;
    m.add("SolveError", m.py().get_type::<SolveError>())?;
    m.add_function(wrap_pyfunction!(solve, m)?)?;
    m.add_function(wrap_pyfunction!(kernel, m)?)?;
    m.add_function(wrap_pyfunction!(materials, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(serve_as_worker, m)?)?;
    m.add_function(wrap_pyfunction!(read_scan, m)?)?;
    m.add_function(wrap_pyfunction!(write_x3p, m)?)?;
    Ok(())
}
