//! Property test of config loading (#20): the shipped configs, mutated the
//! way a hurried or hostile user would (deleted and duplicated lines, swapped
//! value types, extreme and non-finite numbers, unicode, truncation, random
//! `--set` overrides), never make loading panic, and every error names a key,
//! a line or a path.
//!
//! A seeded generator keeps failures reproducible. `cargo test` runs
//! `MPCONTACT_FUZZ_CASES` mutations (default 400, well under a second) from
//! `MPCONTACT_FUZZ_SEED`; `bench/fuzz-config.sh` runs many more seeds.

use coordinator::config::Config;
use std::path::Path;

/// xorshift64*: small, seeded, good enough to pick mutations.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

const VALUES: &[&str] = &[
    "0",
    "-0.0",
    "1e308",
    "-1e308",
    "1e-300",
    "nan",
    "inf",
    "-inf",
    "9223372036854775807",
    "-9223372036854775808",
    "4096",
    "3",
    "\"text\"",
    "\"\"",
    "true",
    "[]",
    "[1, 2, 3]",
    "{}",
    "{ start = 0 }",
    "{ start = 0, stop = 180, step = 1e-300 }",
    "\"Cu\"",
    "[\"Cu\", \"Cu\"]",
    "\"é☃𝄞\"",
    "0.9999999999",
    "1e20",
    "-1",
    "[0.0, 0.0]",
    "{ youngs_gpa = nan, poisson = 0.3 }",
    "[[1, 0], [0, 1]]",
];

const KEYS: &[&str] = &[
    "grid.points",
    "grid.spacing_um",
    "indenter.radius_mm",
    "load.normal_n",
    "load.friction",
    "load.tangential_ratio",
    "sweep.materials",
    "sweep.surfaces",
    "sweep.angles_deg",
    "solver.coupling",
    "solver.tolerance",
    "solver.max_iterations",
    "solver.coupling_tolerance",
    "run.case_timeout_s",
    "output.save_fields",
    "materials.x.isotropic",
    "surfaces.y.shape",
    "grid.é",
    "a.b.c",
];

/// Words of which an error must name at least one: the config's sections and
/// keys, "line" (a parse error) or a path separator.
const NAMES: &[&str] = &[
    "line",
    "/",
    "grid",
    "points",
    "spacing_um",
    "indenter",
    "radius_mm",
    "load",
    "normal_n",
    "friction",
    "tangential_ratio",
    "sweep",
    "materials",
    "surfaces",
    "angles_deg",
    "solver",
    "tolerance",
    "iterations",
    "coupling",
    "run",
    "case_timeout_s",
    "output",
    "save_fields",
    "--set",
    "key",
];

fn mutate(text: &str, rng: &mut Rng) -> (String, Vec<String>) {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut sets = Vec::new();
    for _ in 0..1 + rng.below(3) {
        if lines.is_empty() {
            lines.push(String::new());
        }
        let i = rng.below(lines.len());
        match rng.below(7) {
            0 => {
                lines.remove(i);
            }
            1 => {
                let l = lines[i].clone();
                lines.insert(i, l);
            }
            2 | 3 => {
                if let Some((k, _)) = lines[i].split_once('=') {
                    lines[i] = format!("{k}= {}", rng.pick(VALUES));
                }
            }
            4 => {
                let at = lines[i].char_indices().map(|(j, _)| j).collect::<Vec<_>>();
                let j = if at.is_empty() { 0 } else { *rng.pick(&at) };
                lines[i].insert_str(j, "é☃𝄞");
            }
            5 => sets.push(format!("{}={}", rng.pick(KEYS), rng.pick(VALUES))),
            _ => {
                let joined = lines.join("\n");
                let cuts: Vec<usize> = joined.char_indices().map(|(j, _)| j).collect();
                let cut = if cuts.is_empty() { 0 } else { *rng.pick(&cuts) };
                lines = joined[..cut].lines().map(str::to_string).collect();
                if lines.is_empty() {
                    lines.push(String::new());
                }
            }
        }
    }
    (lines.join("\n"), sets)
}

#[test]
fn mutated_configs_never_panic_and_every_error_names_a_key_line_or_path() {
    let cases: usize = std::env::var("MPCONTACT_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(400);
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
    let mut shipped: Vec<(String, String)> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read_to_string(&p).unwrap())
        })
        .collect();
    shipped.sort();
    assert!(
        shipped.len() >= 5,
        "shipped configs not found in {}",
        dir.display()
    );
    let seed = std::env::var("MPCONTACT_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0x9e37_79b9_7f4a_7c15_u64);
    let mut rng = Rng(seed | 1);
    let (mut errors, mut loaded) = (0, 0);
    for case in 0..cases {
        let (name, text) = &shipped[case % shipped.len()];
        let (mutated, sets) = mutate(text, &mut rng);
        let outcome = std::panic::catch_unwind(|| {
            Config::parse_in(&mutated, &sets, &dir).and_then(|c| c.cases().map(|v| v.len()))
        });
        let what = format!("case {case} ({name}, --set {sets:?}):\n{mutated}");
        match outcome {
            Err(_) => panic!("config loading panicked on {what}"),
            Ok(Ok(_)) => loaded += 1,
            Ok(Err(e)) => {
                errors += 1;
                let msg = format!("{e:#}");
                assert!(
                    NAMES.iter().any(|n| msg.contains(n)),
                    "the error names no key, line or path: {msg}\n{what}"
                );
            }
        }
    }
    eprintln!("{cases} mutated configs: {loaded} loaded, {errors} refused with a named error");
    assert!(errors > cases / 4, "the mutations rarely broke anything");
}
