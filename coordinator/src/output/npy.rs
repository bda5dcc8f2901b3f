//! `.npy` files: writing the `n x n` fields of `solve` and `run`, and reading
//! the height maps of `[surfaces.*] file`. Owns only the file format; knows
//! no IPC, no config keys and no physics.

use std::io::BufWriter;
use std::path::Path;

use anyhow::{bail, Context, Result};
use npyz::WriterBuilder;
use solver::Fields;

/// Writes one `n x n` field as a 2-D float64 `.npy` (rows = y, columns = x).
pub fn write_npy(path: &Path, n: usize, data: &[f64]) -> Result<()> {
    write_npy_2d(path, n, n, data)
}

/// Writes a `rows x cols` array (row major) as a 2-D float64 `.npy`.
pub fn write_npy_2d(path: &Path, rows: usize, cols: usize, data: &[f64]) -> Result<()> {
    crate::atomic::replace_with(path, |tmp| {
        let file = std::fs::File::create(tmp)?;
        let mut w = npyz::WriteOptions::new()
            .default_dtype()
            .shape(&[rows as u64, cols as u64])
            .writer(BufWriter::new(file))
            .begin_nd()?;
        w.extend(data.iter().copied())?;
        w.finish()?;
        Ok(())
    })
}

/// Writes every field of a case into `dir` as `<name>.npy`.
pub fn write_fields(dir: &Path, fields: &Fields) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    for (name, data) in fields.named() {
        write_npy(&dir.join(format!("{name}.npy")), fields.n, data)?;
    }
    Ok(())
}

/// Reads an `n x n` float64 (or float32) `.npy` file in C order. Only a
/// regular file is opened (a FIFO would block, `/dev/zero` never end), and
/// its header is checked against the grid before any data is read, so a
/// wrong file costs no more than its header.
pub fn read_grid_npy(path: &Path, n: usize) -> Result<Vec<f64>> {
    let meta =
        std::fs::metadata(path).with_context(|| format!("cannot read {}", path.display()))?;
    if !meta.is_file() {
        bail!("{} is not a regular file", path.display());
    }
    let file =
        std::fs::File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
    let npy = npyz::NpyFile::new(std::io::BufReader::new(file))
        .with_context(|| format!("{} is not a .npy file", path.display()))?;
    let shape = npy.shape().to_vec();
    if shape != [n as u64, n as u64] {
        bail!(
            "{} has shape {shape:?} but the grid is {n} x {n} (grid.points)",
            path.display()
        );
    }
    if npy.order() != npyz::Order::C {
        bail!("Fortran-ordered arrays are not supported; save with numpy's default C order");
    }
    let size = match npy.dtype() {
        npyz::DType::Plain(t) if t.type_char() == npyz::TypeChar::Float => t.size_field(),
        other => bail!(
            "{}: expected float64 or float32 values, got {}",
            path.display(),
            other.descr()
        ),
    };
    if meta.len() < (n * n) as u64 * size {
        bail!(
            "{} is {} bytes, too short for {n} x {n} values",
            path.display(),
            meta.len()
        );
    }
    let values: Vec<f64> = if size == 4 {
        npy.into_vec::<f32>()?.into_iter().map(f64::from).collect()
    } else {
        npy.into_vec::<f64>()?
    };
    Ok(values)
}
