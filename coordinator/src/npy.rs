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
    let file =
        std::fs::File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
    let mut w = npyz::WriteOptions::new()
        .default_dtype()
        .shape(&[n as u64, n as u64])
        .writer(BufWriter::new(file))
        .begin_nd()?;
    w.extend(data.iter().copied())?;
    w.finish()?;
    Ok(())
}

/// Writes every field of a case into `dir` as `<name>.npy`.
pub fn write_fields(dir: &Path, fields: &Fields) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    for (name, data) in fields.named() {
        write_npy(&dir.join(format!("{name}.npy")), fields.n, data)?;
    }
    Ok(())
}

/// Reads a float64 (or float32) `.npy` file: shape and values in C order.
pub fn read_npy_f64(path: &Path) -> Result<(Vec<u64>, Vec<f64>)> {
    let bytes = std::fs::read(path)?;
    let npy = npyz::NpyFile::new(&bytes[..])?;
    let shape = npy.shape().to_vec();
    if npy.order() != npyz::Order::C {
        bail!("Fortran-ordered arrays are not supported; save with numpy's default C order");
    }
    let values: Vec<f64> = match npy.dtype() {
        npyz::DType::Plain(t) if t.type_char() == npyz::TypeChar::Float && t.size_field() == 4 => {
            npy.into_vec::<f32>()?.into_iter().map(f64::from).collect()
        }
        _ => npy.into_vec::<f64>()?,
    };
    Ok((shape, values))
}
