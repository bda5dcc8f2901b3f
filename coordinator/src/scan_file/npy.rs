//! `.npy` arrays of heights: the 2-D float reader that height maps
//! (`shape = "heightmap"`, one height per cell) and scans (`shape =
//! "scan"`, heights in µm on pixels of a given size, NaN where missing)
//! share; the header is checked before any data is read.

use super::{open_regular, ScanFileError};
use solver::Scan;
use std::path::Path;

/// The `(rows, columns)` and values (C order) of the 2-D float64 or
/// float32 array in `path`; `check` sees the shape from the header first
/// and may refuse it before the data is read.
pub fn read_2d(
    path: &Path,
    check: impl FnOnce(&[u64]) -> Result<(), String>,
) -> Result<(usize, usize, Vec<f64>), ScanFileError> {
    let (file, len) = open_regular(path)?;
    let bad = |reason: String| ScanFileError::new(path, reason);
    let npy = npyz::NpyFile::new(std::io::BufReader::new(file))
        .map_err(|e| bad(format!("not a .npy file ({e})")))?;
    let shape = npy.shape().to_vec();
    check(&shape).map_err(bad)?;
    let [rows, cols] = shape[..] else {
        return Err(bad(format!(
            "an array of shape {shape:?}: a 2-D array of heights is needed"
        )));
    };
    if npy.order() != npyz::Order::C {
        return Err(bad(
            "Fortran-ordered arrays are not supported; save with numpy's default C order".into(),
        ));
    }
    let size = match npy.dtype() {
        npyz::DType::Plain(t) if t.type_char() == npyz::TypeChar::Float => t.size_field(),
        other => {
            return Err(bad(format!(
                "expected float64 or float32 values, got {}",
                other.descr()
            )))
        }
    };
    if len < rows * cols * size {
        return Err(bad(format!(
            "{len} bytes, too short for {rows} x {cols} values"
        )));
    }
    let values: Vec<f64> = if size == 4 {
        npy.into_vec::<f32>()
            .map_err(|e| bad(e.to_string()))?
            .into_iter()
            .map(f64::from)
            .collect()
    } else {
        npy.into_vec::<f64>().map_err(|e| bad(e.to_string()))?
    };
    Ok((rows as usize, cols as usize, values))
}

/// A scan from a 2-D `.npy` of heights in µm (rows along y, NaN where
/// missing) on pixels of `pixel_m` (x, y).
pub fn read_scan(path: &Path, pixel_m: [f64; 2]) -> Result<Scan, ScanFileError> {
    let (rows, cols, values) = read_2d(path, |shape| match shape.len() {
        2 => Ok(()),
        1 => Err(format!(
            "a 1-D profile ({} points): contact needs a 2-D map of heights",
            shape[0]
        )),
        _ => Err(format!(
            "an array of shape {shape:?}: a 2-D array of heights is needed"
        )),
    })?;
    let heights = values.into_iter().map(|v| v * 1e-6).collect();
    Scan::new(cols, rows, pixel_m[0], pixel_m[1], heights)
        .map_err(|e| ScanFileError::new(path, reason_of(e)))
}

/// The reason of a solver error, without its field (the file names it).
pub(crate) fn reason_of(e: solver::SolverError) -> String {
    match e {
        solver::SolverError::Invalid { reason, .. } => reason,
        other => other.to_string(),
    }
}
