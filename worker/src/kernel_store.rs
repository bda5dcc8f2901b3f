//! On-disk store of kernel spectra (the three real and three complex half
//! spectra an operator holds), keyed by material constants and grid, so a
//! second run (or a second worker) does not pay an anisotropic kernel build
//! again. Files live in `$MPCONTACT_CACHE_DIR`, else
//! `$XDG_CACHE_HOME/mpcontact/kernels`, else `~/.cache/mpcontact/kernels`.
//!
//! An entry is written to a private temporary file and renamed into place, so
//! a reader never sees half a file. It ends with a CRC-32 of everything
//! before it (header and data), verified on every load: a file that does not
//! match its key, or whose checksum fails, is not used (the latter with a
//! warning) and is rebuilt and rewritten. A directory that another user can
//! write to (group- or world-writable, or owned by someone else) is refused:
//! its kernels could be replaced under us.
//!
//! Each kernel is built once for all the processes sharing the directory: a
//! process about to build one takes an exclusive `flock` on `<entry>.lock`
//! beside the entry, and the others wait for the entry instead of building it
//! too. The kernel releases the lock when its holder exits or dies, so a
//! crashed builder leaves no stale lock: the next waiter takes it, finds no
//! entry and builds. Lock files are left in place (removing one while
//! another process opens it would let two builders in).

use num_complex::Complex64;
use solver::{BuildLock, KernelKey, KernelStore, Spectra};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Format 3 adds the trailing checksum (format 2 files are rebuilt).
const MAGIC: &[u8; 8] = b"MPCKERN3";

/// Values read per chunk.
const CHUNK: usize = 1 << 16;

/// Kernel spectra as files in one directory.
pub struct FileStore {
    dir: PathBuf,
    /// Whether the directory may be used (checked once, on first use).
    usable: OnceLock<bool>,
}

/// A reader that feeds everything it reads into a CRC-32.
struct Crc<R> {
    inner: R,
    crc: crc32fast::Hasher,
}

impl<R: Read> Read for Crc<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.crc.update(&buf[..n]);
        Ok(n)
    }
}

/// A writer that feeds everything it writes into a CRC-32.
struct CrcWriter<W> {
    inner: W,
    crc: crc32fast::Hasher,
}

impl<W: Write> Write for CrcWriter<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.crc.update(&buf[..n]);
        Ok(n)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

/// What a read found.
enum Entry {
    /// A valid entry for the key.
    Found(Spectra),
    /// No entry for this key (another key, format or length).
    Absent,
    /// An entry for this key whose checksum or values are wrong.
    Corrupt(&'static str),
}

/// Why `dir` must not hold our kernels, if it must not: writable by group or
/// others, owned by another user, or not a directory.
fn unsafe_dir(dir: &Path) -> Option<String> {
    use std::os::unix::fs::MetadataExt;
    let meta = std::fs::metadata(dir).ok()?;
    if !meta.is_dir() {
        return Some("it is not a directory".into());
    }
    let mode = meta.mode() & 0o7777;
    if mode & 0o022 != 0 {
        return Some(format!(
            "it is writable by other users (mode {mode:o}); use a private directory (chmod go-w)"
        ));
    }
    // SAFETY: geteuid has no preconditions and cannot fail.
    let me = unsafe { libc::geteuid() };
    if meta.uid() != me {
        return Some(format!(
            "it belongs to user id {}, not to this user ({me})",
            meta.uid()
        ));
    }
    None
}

impl FileStore {
    /// A store in `dir` (created on first save, private to this user).
    pub fn new(dir: PathBuf) -> Self {
        FileStore {
            dir,
            usable: OnceLock::new(),
        }
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

    /// True when the directory exists (or was just created) private to this
    /// user; otherwise warns once and the store is not used.
    fn usable(&self) -> bool {
        *self.usable.get_or_init(|| {
            if !self.dir.exists() {
                use std::os::unix::fs::DirBuilderExt;
                if let Err(e) = std::fs::DirBuilder::new()
                    .recursive(true)
                    .mode(0o700)
                    .create(&self.dir)
                {
                    eprintln!(
                        "warning: kernel cache {} cannot be created ({e}); kernels are not stored",
                        self.dir.display()
                    );
                    return false;
                }
            }
            match unsafe_dir(&self.dir) {
                Some(why) => {
                    eprintln!(
                        "warning: kernel cache {} is not used: {why}",
                        self.dir.display()
                    );
                    false
                }
                None => true,
            }
        })
    }

    /// Whether an entry for `key` is stored (its header names the key; the
    /// data are checked only when it is loaded). For dry runs.
    pub fn holds(&self, key: &KernelKey) -> bool {
        let Ok(mut f) = std::fs::File::open(self.path(key)) else {
            return false;
        };
        let mut head = vec![0u8; 16 + key.as_str().len()];
        f.read_exact(&mut head).is_ok()
            && &head[..8] == MAGIC
            && head[8..16] == (key.as_str().len() as u64).to_le_bytes()
            && &head[16..] == key.as_str().as_bytes()
    }

    fn path(&self, key: &KernelKey) -> PathBuf {
        // FNV-1a of the key names the file; the key itself is stored and checked.
        let mut h: u64 = 0xcbf29ce484222325;
        for b in key.as_str().bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x100000001b3);
        }
        self.dir.join(format!("{h:016x}.kern"))
    }

    /// Takes the build lock of `key` without waiting (see the module docs).
    fn lock(&self, key: &KernelKey) -> BuildLock {
        use std::os::fd::AsRawFd;
        use std::os::unix::fs::OpenOptionsExt;
        let path = self.path(key).with_extension("lock");
        let file = match std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .mode(0o600)
            .open(&path)
        {
            Ok(f) => f,
            Err(_) => return BuildLock::Unsupported,
        };
        // SAFETY: flock on a descriptor we own; it has no memory effects.
        let rc = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
        if rc == 0 {
            // Held as long as the file stays open.
            return BuildLock::Held(Box::new(file));
        }
        match std::io::Error::last_os_error().raw_os_error() {
            Some(libc::EWOULDBLOCK) | Some(libc::EINTR) => BuildLock::Busy,
            // A file system without flock: build without the lock.
            _ => BuildLock::Unsupported,
        }
    }

    fn read(path: &Path, key: &KernelKey, len: usize) -> std::io::Result<Entry> {
        let key = key.as_str();
        let file = std::io::BufReader::new(std::fs::File::open(path)?);
        let mut f = Crc {
            inner: file,
            crc: crc32fast::Hasher::new(),
        };
        let mut magic = [0u8; 8];
        f.read_exact(&mut magic)?;
        let mut word = [0u8; 8];
        f.read_exact(&mut word)?;
        let klen = u64::from_le_bytes(word) as usize;
        if &magic != MAGIC || klen != key.len() {
            return Ok(Entry::Absent);
        }
        let mut kbytes = vec![0u8; klen];
        f.read_exact(&mut kbytes)?;
        f.read_exact(&mut word)?;
        if kbytes != key.as_bytes() || u64::from_le_bytes(word) as usize != len {
            return Ok(Entry::Absent);
        }
        let mut buf = vec![0u8; CHUNK * 8];
        // Reads `out.len()` values, chunk by chunk (no whole-file buffer).
        let mut read_values = |out: &mut [f64]| -> std::io::Result<()> {
            for part in out.chunks_mut(CHUNK) {
                let bytes = &mut buf[..part.len() * 8];
                f.read_exact(bytes)?;
                for (v, c) in part.iter_mut().zip(bytes.chunks_exact(8)) {
                    *v = f64::from_le_bytes(c.try_into().expect("8 bytes"));
                }
            }
            Ok(())
        };
        let mut diag: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; len]);
        for d in diag.iter_mut() {
            read_values(d)?;
        }
        let mut off: [Vec<Complex64>; 3] = std::array::from_fn(|_| vec![Complex64::default(); len]);
        let mut pair = [0.0; 2 * 4096];
        for o in off.iter_mut() {
            for part in o.chunks_mut(4096) {
                let vals = &mut pair[..2 * part.len()];
                read_values(vals)?;
                for (z, v) in part.iter_mut().zip(vals.chunks_exact(2)) {
                    *z = Complex64::new(v[0], v[1]);
                }
            }
        }
        let Crc {
            inner: mut file,
            crc,
        } = f;
        let mut stored = [0u8; 4];
        if file.read_exact(&mut stored).is_err() {
            return Ok(Entry::Corrupt("it is cut short"));
        }
        if u32::from_le_bytes(stored) != crc.finalize() {
            return Ok(Entry::Corrupt("its checksum does not match its contents"));
        }
        // Nothing may follow: a longer file is not this entry.
        if file.read(&mut word)? != 0 {
            return Ok(Entry::Corrupt("it is longer than its entry"));
        }
        let finite = diag.iter().all(|d| d.iter().all(|v| v.is_finite()))
            && off
                .iter()
                .all(|o| o.iter().all(|z| z.re.is_finite() && z.im.is_finite()));
        if !finite {
            return Ok(Entry::Corrupt("it holds non-finite values"));
        }
        Ok(Entry::Found(Spectra { diag, off }))
    }

    fn write(&self, key: &KernelKey, spectra: &Spectra) -> std::io::Result<()> {
        let path = self.path(key);
        let key = key.as_str();
        // Write to a private temporary name, then rename: readers never see half a file.
        // Unique among the processes of every node sharing the directory
        // (shards of a cluster job may write the same kernel at once).
        let host = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap_or_default();
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        let tmp = path.with_extension(format!(
            "tmp-{}-{}-{nanos}",
            host.trim(),
            std::process::id()
        ));
        let result = (|| {
            let file = std::io::BufWriter::new(std::fs::File::create(&tmp)?);
            let mut f = CrcWriter {
                inner: file,
                crc: crc32fast::Hasher::new(),
            };
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
            let CrcWriter { mut inner, crc } = f;
            inner.write_all(&crc.finalize().to_le_bytes())?;
            inner.into_inner().map_err(|e| e.into_error())?.sync_all()?;
            std::fs::rename(&tmp, &path)
        })();
        if result.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        result
    }
}

impl KernelStore for FileStore {
    fn load(&self, key: &KernelKey, len: usize) -> Option<Spectra> {
        if !self.usable() {
            return None;
        }
        let path = self.path(key);
        match Self::read(&path, key, len) {
            Ok(Entry::Found(s)) => Some(s),
            Ok(Entry::Corrupt(why)) => {
                eprintln!(
                    "warning: kernel cache entry {} is not used: {why}; rebuilding it",
                    path.display()
                );
                None
            }
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
                eprintln!(
                    "warning: kernel cache entry {} is not used: it is cut short; rebuilding it",
                    path.display()
                );
                None
            }
            Ok(Entry::Absent) | Err(_) => None,
        }
    }

    fn try_lock(&self, key: &KernelKey) -> BuildLock {
        if !self.usable() {
            return BuildLock::Unsupported;
        }
        self.lock(key)
    }

    fn save(&self, key: &KernelKey, spectra: &Spectra) {
        if !self.usable() {
            return;
        }
        if let Err(e) = self.write(key, spectra) {
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
                ..Numerics::default()
            },
            history: None,
            indenter: None,
        }
    }

    #[test]
    fn second_cache_loads_the_stored_kernel_and_gives_identical_results() {
        let (_tmp, dir) = private_store();
        let mut first = solver::KernelCache::with_store(Box::new(FileStore::new(dir.clone())));
        let a = solve_case(&spec(), &mut first).unwrap();
        assert_eq!((first.builds(), first.loads()), (1, 0));
        let mut second = solver::KernelCache::with_store(Box::new(FileStore::new(dir.clone())));
        let b = solve_case(&spec(), &mut second).unwrap();
        assert_eq!((second.builds(), second.loads()), (0, 1));
        assert_eq!(
            a.fields.p, b.fields.p,
            "bit-identical pressure from the stored kernel"
        );
        // A corrupted file is ignored and rebuilt.
        let file = only_file(&dir);
        let bytes = std::fs::read(&file).unwrap();
        std::fs::write(&file, &bytes[..bytes.len() / 2]).unwrap();
        let mut third = solver::KernelCache::with_store(Box::new(FileStore::new(dir.clone())));
        let c = solve_case(&spec(), &mut third).unwrap();
        assert_eq!(third.loads(), 0);
        assert_eq!(a.fields.p, c.fields.p);
    }

    /// A store in a fresh private temporary directory (removed on drop).
    fn private_store() -> (tempfile::TempDir, PathBuf) {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("kernels");
        (tmp, dir)
    }

    fn cache_in(dir: &Path) -> solver::KernelCache {
        solver::KernelCache::with_store(Box::new(FileStore::new(dir.to_path_buf())))
    }

    /// The one entry in `dir` (lock files aside).
    fn only_file(dir: &Path) -> PathBuf {
        let files: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "kern"))
            .collect();
        assert_eq!(files.len(), 1, "{files:?}");
        files[0].clone()
    }

    #[test]
    fn issue20_item2_one_flipped_sign_bit_is_detected_and_the_kernel_rebuilt() {
        let (_tmp, dir) = private_store();
        let a = solve_case(&spec(), &mut cache_in(&dir)).unwrap();
        let file = only_file(&dir);
        let mut bytes = std::fs::read(&file).unwrap();
        // The sign bit of one value in the middle of the data (little endian:
        // the last byte of an 8-byte value).
        let header = 8 + 8 + KernelKey::of(&spec()).as_str().len() + 8;
        let k = header + (bytes.len() - header - 4) / 16 * 8 + 7;
        bytes[k] ^= 0x80;
        std::fs::write(&file, &bytes).unwrap();
        let mut second = cache_in(&dir);
        let b = solve_case(&spec(), &mut second).unwrap();
        assert_eq!(second.loads(), 0, "the corrupt entry was not used");
        assert_eq!(
            a.fields.p, b.fields.p,
            "the rebuilt kernel gives the same result"
        );
        // It was rewritten: a third cache loads it, and it verifies.
        let mut third = cache_in(&dir);
        let c = solve_case(&spec(), &mut third).unwrap();
        assert_eq!(third.loads(), 1);
        assert_eq!(a.fields.p, c.fields.p);
    }

    #[test]
    fn issue20_item2_a_directory_writable_by_others_is_not_used() {
        use std::os::unix::fs::PermissionsExt;
        let (_tmp, dir) = private_store();
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o777)).unwrap();
        let a = solve_case(&spec(), &mut cache_in(&dir)).unwrap();
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            0,
            "nothing stored"
        );
        let mut second = cache_in(&dir);
        let b = solve_case(&spec(), &mut second).unwrap();
        assert_eq!(second.loads(), 0, "nothing loaded");
        assert_eq!(a.fields.p, b.fields.p);
        assert!(unsafe_dir(&dir)
            .unwrap()
            .contains("writable by other users"));
        // A directory the store creates is private to its user.
        let (_tmp2, fresh) = private_store();
        let _ = solve_case(&spec(), &mut cache_in(&fresh)).unwrap();
        let mode = std::fs::metadata(&fresh).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o700);
        assert!(unsafe_dir(&fresh).is_none());
    }

    #[test]
    fn concurrent_writers_of_one_kernel_never_show_a_reader_half_an_entry() {
        // Shards on a shared file system may store the same kernel at once.
        let (_tmp, dir) = private_store();
        let spec = spec();
        let spectra =
            solver::build_operator(&spec.material, spec.grid).with_spectra(Spectra::clone);
        let key = KernelKey::of(&spec);
        let len = Spectra::len_for(spec.grid.n);
        let store = FileStore::new(dir.clone());
        std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| {
                    for _ in 0..10 {
                        store.save(&key, &spectra);
                    }
                });
            }
            s.spawn(|| {
                for _ in 0..200 {
                    if let Some(read) = store.load(&key, len) {
                        assert!(read == spectra, "a reader saw a different entry");
                    }
                }
            });
        });
        assert!(store.load(&key, len).is_some_and(|r| r == spectra));
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left.len(), 1, "temporary files left: {left:?}");
    }

    #[test]
    fn two_caches_racing_on_a_cold_store_build_the_kernel_once() {
        // Two workers of a sweep needing the same anisotropic kernel at once.
        for _ in 0..3 {
            let (_tmp, dir) = private_store();
            let start = std::sync::Barrier::new(2);
            let counts: Vec<(usize, usize)> = std::thread::scope(|s| {
                let racers: Vec<_> = (0..2)
                    .map(|_| {
                        s.spawn(|| {
                            let mut cache = cache_in(&dir);
                            start.wait();
                            cache.resident(&spec()).unwrap();
                            (cache.builds(), cache.loads())
                        })
                    })
                    .collect();
                racers.into_iter().map(|r| r.join().unwrap()).collect()
            });
            let builds: usize = counts.iter().map(|c| c.0).sum();
            let loads: usize = counts.iter().map(|c| c.1).sum();
            assert_eq!((builds, loads), (1, 1), "{counts:?}");
        }
    }

    #[test]
    fn a_waiter_builds_the_kernel_itself_when_the_builder_dies_without_storing_it() {
        // The lock is a flock: it ends when its holder's descriptor closes,
        // which is what the kernel does when a process exits or is killed.
        let (_tmp, dir) = private_store();
        let holder = FileStore::new(dir.clone());
        let BuildLock::Held(guard) = holder.try_lock(&KernelKey::of(&spec())) else {
            panic!("a cold store's lock is free");
        };
        let waiter = std::thread::spawn({
            let dir = dir.clone();
            move || {
                let mut cache = cache_in(&dir);
                cache.resident(&spec()).unwrap();
                (cache.builds(), cache.loads())
            }
        });
        std::thread::sleep(std::time::Duration::from_millis(300));
        assert!(
            !waiter.is_finished(),
            "the waiter waits while the lock is held"
        );
        drop(guard);
        assert_eq!(waiter.join().unwrap(), (1, 0), "built by the waiter");
        assert!(only_file(&dir).exists());
    }
}
