//! On-disk store of kernel spectra (the three real and three complex half
//! spectra an operator holds), keyed by material constants and grid, so a
//! second run (or a second worker) does not pay an anisotropic kernel build
//! again. Files live in `$MPCONTACT_CACHE_DIR`, else
//! `$XDG_CACHE_HOME/mpcontact/kernels`, else `~/.cache/mpcontact/kernels`.
//! A file that does not match its key exactly is ignored and rewritten.

use num_complex::Complex64;
use solver::{KernelKey, KernelStore, Spectra};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

const MAGIC: &[u8; 8] = b"MPCKERN2";

/// Values read per chunk.
const CHUNK: usize = 1 << 16;

/// Kernel spectra as files in one directory.
pub struct FileStore {
    dir: PathBuf,
}

impl FileStore {
    /// A store in `dir` (created on first save).
    pub fn new(dir: PathBuf) -> Self {
        FileStore { dir }
    }

    /// The default location (see the module docs); `None` when no home is known.
    pub fn default_location() -> Option<PathBuf> {
        if let Some(d) = std::env::var_os("MPCONTACT_CACHE_DIR") {
            return Some(PathBuf::from(d));
        }
        if let Some(d) = std::env::var_os("XDG_CACHE_HOME") {
            return Some(PathBuf::from(d).join("mpcontact/kernels"));
        }
        std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache/mpcontact/kernels"))
    }

    /// A cache backed by the default store, or a plain in-memory cache.
    pub fn cache() -> solver::KernelCache {
        match Self::default_location() {
            Some(dir) => solver::KernelCache::with_store(Box::new(FileStore::new(dir))),
            None => solver::KernelCache::new(),
        }
    }

    fn path(&self, key: &KernelKey) -> PathBuf {
        let key = key.as_str();
        // FNV-1a of the key names the file; the key itself is stored and checked.
        let mut h: u64 = 0xcbf29ce484222325;
        for b in key.bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x100000001b3);
        }
        self.dir.join(format!("{h:016x}.kern"))
    }

    fn read(path: &Path, key: &KernelKey, len: usize) -> std::io::Result<Option<Spectra>> {
        let key = key.as_str();
        let mut f = std::io::BufReader::new(std::fs::File::open(path)?);
        let mut magic = [0u8; 8];
        f.read_exact(&mut magic)?;
        let mut word = [0u8; 8];
        f.read_exact(&mut word)?;
        let klen = u64::from_le_bytes(word) as usize;
        if &magic != MAGIC || klen != key.len() {
            return Ok(None);
        }
        let mut kbytes = vec![0u8; klen];
        f.read_exact(&mut kbytes)?;
        f.read_exact(&mut word)?;
        if kbytes != key.as_bytes() || u64::from_le_bytes(word) as usize != len {
            return Ok(None);
        }
        let mut buf = vec![0u8; CHUNK * 8];
        // Reads `out.len()` finite values, chunk by chunk (no whole-file buffer).
        let mut read_values = |out: &mut [f64]| -> std::io::Result<bool> {
            for part in out.chunks_mut(CHUNK) {
                let bytes = &mut buf[..part.len() * 8];
                f.read_exact(bytes)?;
                for (v, c) in part.iter_mut().zip(bytes.chunks_exact(8)) {
                    *v = f64::from_le_bytes(c.try_into().expect("8 bytes"));
                }
                if part.iter().any(|v| !v.is_finite()) {
                    return Ok(false);
                }
            }
            Ok(true)
        };
        let mut diag: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; len]);
        for d in diag.iter_mut() {
            if !read_values(d)? {
                return Ok(None);
            }
        }
        let mut off: [Vec<Complex64>; 3] = std::array::from_fn(|_| vec![Complex64::default(); len]);
        let mut pair = [0.0; 2 * 4096];
        for o in off.iter_mut() {
            for part in o.chunks_mut(4096) {
                let vals = &mut pair[..2 * part.len()];
                if !read_values(vals)? {
                    return Ok(None);
                }
                for (z, v) in part.iter_mut().zip(vals.chunks_exact(2)) {
                    *z = Complex64::new(v[0], v[1]);
                }
            }
        }
        // Nothing may follow: a longer file is not this entry.
        if f.read(&mut word)? != 0 {
            return Ok(None);
        }
        Ok(Some(Spectra { diag, off }))
    }
}

impl KernelStore for FileStore {
    fn load(&self, key: &KernelKey, len: usize) -> Option<Spectra> {
        Self::read(&self.path(key), key, len).ok().flatten()
    }

    fn save(&self, key: &KernelKey, spectra: &Spectra) {
        let write = || -> std::io::Result<()> {
            std::fs::create_dir_all(&self.dir)?;
            let path = self.path(key);
            let key = key.as_str();
            // Write to a private temporary name, then rename: readers never see half a file.
            let tmp = path.with_extension(format!("tmp{}", std::process::id()));
            {
                let mut f = std::io::BufWriter::new(std::fs::File::create(&tmp)?);
                f.write_all(MAGIC)?;
                f.write_all(&(key.len() as u64).to_le_bytes())?;
                f.write_all(key.as_bytes())?;
                f.write_all(&(spectra.diag[0].len() as u64).to_le_bytes())?;
                for d in &spectra.diag {
                    for v in d {
                        f.write_all(&v.to_le_bytes())?;
                    }
                }
                for o in &spectra.off {
                    for z in o {
                        f.write_all(&z.re.to_le_bytes())?;
                        f.write_all(&z.im.to_le_bytes())?;
                    }
                }
                f.flush()?;
            }
            std::fs::rename(&tmp, &path)
        };
        if let Err(e) = write() {
            eprintln!(
                "warning: cannot store kernel in {}: {e}",
                self.dir.display()
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use solver::{solve_case, CaseSpec, Grid, Load, Numerics, Surface};

    fn spec() -> CaseSpec {
        CaseSpec {
            material: solver::presets::material("Cu(111)").unwrap(),
            surface: Surface::Flat,
            grid: Grid::square(32, 200e-6),
            load: Load {
                indenter_radius_m: 0.2,
                normal_force_n: 6000.0,
                friction: 0.3,
                tangential_ratio: 0.0,
                angle_deg: 0.0,
            },
            numerics: Numerics {
                coupling: false,
                tolerance: 1e-10,
                tangential_tolerance: 1e-6,
                max_iterations: 2000,
                coupling_tolerance: 1e-8,
                max_coupling_iterations: 5,
            },
        }
    }

    #[test]
    fn second_cache_loads_the_stored_kernel_and_gives_identical_results() {
        let dir = std::env::temp_dir().join(format!("mpcontact-kstore-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let mut first = solver::KernelCache::with_store(Box::new(FileStore::new(dir.clone())));
        let a = solve_case(&spec(), &mut first).unwrap();
        assert_eq!((first.builds(), first.loads()), (1, 0));
        let mut second = solver::KernelCache::with_store(Box::new(FileStore::new(dir.clone())));
        let b = solve_case(&spec(), &mut second).unwrap();
        assert_eq!((second.builds(), second.loads()), (1, 1));
        assert_eq!(
            a.fields.p, b.fields.p,
            "bit-identical pressure from the stored kernel"
        );
        // A corrupted file is ignored and rebuilt.
        let file = std::fs::read_dir(&dir)
            .unwrap()
            .next()
            .unwrap()
            .unwrap()
            .path();
        let bytes = std::fs::read(&file).unwrap();
        std::fs::write(&file, &bytes[..bytes.len() / 2]).unwrap();
        let mut third = solver::KernelCache::with_store(Box::new(FileStore::new(dir.clone())));
        let c = solve_case(&spec(), &mut third).unwrap();
        assert_eq!(third.loads(), 0);
        assert_eq!(a.fields.p, c.fields.p);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
