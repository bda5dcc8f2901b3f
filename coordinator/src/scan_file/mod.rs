//! Measured surfaces from files: the open formats the CLI reads itself —
//! ISO 25178-72 `.x3p` ([`x3p`]) and `.npy` height arrays with their
//! pixel size given ([`npy`]) — into a [`solver::Scan`]. Reading only:
//! preparing a scan for a case (levelling, missing points, resampling) is
//! `solver::Scan::prepared` and `solver::resample`, called by the config.

pub mod npy;
pub mod x3p;

use solver::Scan;
use std::path::Path;
use thiserror::Error;

/// A scan file that cannot be read, with the file and what is wrong.
#[derive(Debug, Error)]
#[error("{path}: {reason}")]
pub struct ScanFileError {
    /// The file, as given.
    pub path: String,
    /// What is wrong with it.
    pub reason: String,
}

impl ScanFileError {
    pub(crate) fn new(path: &Path, reason: impl Into<String>) -> Self {
        ScanFileError {
            path: path.display().to_string(),
            reason: reason.into(),
        }
    }
}

/// The formats [`read_scan`] reads, for messages.
pub const FORMATS: &str = "ISO 25178-72 .x3p (pixel sizes and units from the file) and .npy (heights in µm, rows along y, with surfaces.NAME.pixel_um); any format SurfaceTopography reads converts to .x3p in one line: python -m mpcontact.convert FILE OUT.x3p";

/// The formats of scan files, by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// ISO 25178-72 XML 3D surface profile.
    X3p,
    /// A 2-D numpy array of heights in µm.
    Npy,
}

impl Format {
    /// The format of `path` by its extension (case-insensitive), or an
    /// error that lists what is read.
    pub fn of(path: &Path) -> Result<Format, ScanFileError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("x3p") => Ok(Format::X3p),
            Some("npy") => Ok(Format::Npy),
            Some(other) => Err(ScanFileError::new(
                path,
                format!("unknown scan format `.{other}`: mpcontact reads {FORMATS}"),
            )),
            None => Err(ScanFileError::new(
                path,
                format!("no extension to tell the format by: mpcontact reads {FORMATS}"),
            )),
        }
    }
}

/// Reads the scan at `path`: an `.x3p` as it says, an `.npy` with the
/// pixel size `pixel_m` (x, y; required for it).
pub fn read_scan(path: &Path, pixel_m: Option<[f64; 2]>) -> Result<Scan, ScanFileError> {
    match Format::of(path)? {
        Format::X3p => x3p::read(path),
        Format::Npy => {
            let pixel = pixel_m.ok_or_else(|| {
                ScanFileError::new(
                    path,
                    "a .npy holds no pixel size: give surfaces.NAME.pixel_um = [dx, dy]",
                )
            })?;
            npy::read_scan(path, pixel)
        }
    }
}

/// `file` opened only when it is a regular file (a FIFO would block a
/// read, `/dev/zero` never end), with its length.
pub(crate) fn open_regular(path: &Path) -> Result<(std::fs::File, u64), ScanFileError> {
    let meta = std::fs::metadata(path)
        .map_err(|e| ScanFileError::new(path, format!("cannot read: {e}")))?;
    if !meta.is_file() {
        return Err(ScanFileError::new(path, "not a regular file"));
    }
    let file = std::fs::File::open(path)
        .map_err(|e| ScanFileError::new(path, format!("cannot read: {e}")))?;
    Ok((file, meta.len()))
}
