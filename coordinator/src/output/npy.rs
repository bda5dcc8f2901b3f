//! `.npy` files: writing the `n x n` fields of `solve` and `run` and the
//! stress arrays (float64, C order), whole or not at all. Owns only the
//! file format; knows no IPC, no config keys and no physics. (Reading a
//! height map is the config's: `config::read_grid_npy`.)

use std::io::BufWriter;
use std::path::Path;

use anyhow::{Context, Result};
use npyz::WriterBuilder;
use solver::Fields;

/// Writes one `n x n` field as a 2-D float64 `.npy` (rows = y, columns = x).
pub fn write_npy(path: &Path, n: usize, data: &[f64]) -> Result<()> {
    write_npy_2d(path, n, n, data)
}

/// Writes a `rows x cols` array (row major) as a 2-D float64 `.npy`.
pub fn write_npy_2d(path: &Path, rows: usize, cols: usize, data: &[f64]) -> Result<()> {
    super::atomic::replace_with(path, |tmp| {
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
    for (name, data) in fields.present() {
        write_npy(&dir.join(format!("{name}.npy")), fields.n, data)?;
    }
    for (cycle, data) in &fields.wear_saved {
        write_npy(&dir.join(format!("wear_cycle_{cycle}.npy")), fields.n, data)?;
    }
    Ok(())
}
