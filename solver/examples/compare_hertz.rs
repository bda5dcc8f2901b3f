//! Side-by-side benchmark driver (our half of `bench/compare.sh`): the Hertz
//! problem of paper Table 1a (E = 210 GPa, ν = 0.3, R = 18 mm, P = 20 N,
//! non-periodic, square domain 4.5 a) at the requested sizes, the FFT-floor
//! ratio of one iteration, and partial slip (F = 0.6 μP, μ = 0.28571).
//! Prints one JSON object per line. Setup (kernel construction) is excluded
//! from the solve times, which are medians of `--reps` runs.
//!
//! `cargo run --release -p mpcontact-solver --example compare_hertz -- --sizes 256,512 --reps 3`
//! (`--reps-one-from N`: sizes from N on are solved once; `--headline-from N`:
//! sizes from N on run only the nested + preconditioned mode.)

use solver::fft2::{timing, Fft2};
use solver::normal::{NormalOptions, NormalProblem};
use solver::tangential::{TangentialProblem, TangentialStart};
use solver::window::contact_window;
use solver::{build_operator, solve_case, CaseSpec, Grid, KernelCache, Load, Material, Numerics};
use solver::{Resident, Surface, Threads};
use std::time::Instant;

const E: f64 = 210.0e9;
const NU: f64 = 0.3;
const R: f64 = 18.0e-3;
const P: f64 = 20.0;
const MU: f64 = 0.28571;
/// PK change tolerance: 1e-9 leaves a relative L1 pressure error of about 4e-9
/// against the converged discrete solution (the peers are matched to ~1e-8).
const TOL: f64 = 1e-9;

fn hertz_radius() -> f64 {
    let es = E / (1.0 - NU * NU);
    (3.0 * P * R / (4.0 * es)).cbrt()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

struct Args {
    sizes: Vec<usize>,
    slip_sizes: Vec<usize>,
    reps: usize,
    threads: usize,
    /// Sizes from this one on are solved once (`--reps-one-from`).
    reps_one_from: usize,
    /// Sizes from this one on run only the headline mode, nested +
    /// preconditioned (`--headline-from`): plain PK takes ~4 min at 4096².
    headline_from: usize,
}

impl Args {
    fn reps(&self, n: usize) -> usize {
        if n >= self.reps_one_from {
            1
        } else {
            self.reps
        }
    }
}

fn parse() -> Result<Args, String> {
    let mut a = Args {
        sizes: vec![256, 512, 1024],
        slip_sizes: vec![128, 256, 512],
        reps: 3,
        threads: 1,
        reps_one_from: usize::MAX,
        headline_from: usize::MAX,
    };
    let list = |v: &str| -> Result<Vec<usize>, String> {
        v.split(',')
            .filter(|s| !s.is_empty())
            .map(|s| s.trim().parse().map_err(|e| format!("bad size {s:?}: {e}")))
            .collect()
    };
    let mut it = std::env::args().skip(1);
    while let Some(k) = it.next() {
        let v = it.next().ok_or_else(|| format!("{k} needs a value"))?;
        match k.as_str() {
            "--sizes" => a.sizes = list(&v)?,
            "--slip-sizes" => a.slip_sizes = list(&v)?,
            "--reps" => a.reps = v.parse().map_err(|e| format!("--reps: {e}"))?,
            "--threads" => a.threads = v.parse().map_err(|e| format!("--threads: {e}"))?,
            "--reps-one-from" => {
                a.reps_one_from = v.parse().map_err(|e| format!("--reps-one-from: {e}"))?
            }
            "--headline-from" => {
                a.headline_from = v.parse().map_err(|e| format!("--headline-from: {e}"))?
            }
            other => return Err(format!("unknown option {other}")),
        }
    }
    if a.reps == 0 {
        return Err("--reps must be at least 1".into());
    }
    Ok(a)
}

fn grid(n: usize) -> Grid {
    let d = 4.5 * hertz_radius() / n as f64;
    Grid { n, dx: d, dy: d }
}

fn gap(g: Grid) -> Vec<f64> {
    (0..g.len())
        .map(|i| {
            let (x, y) = (g.x(i % g.n), g.y(i / g.n));
            (x * x + y * y) / (2.0 * R)
        })
        .collect()
}

fn hertz(n: usize, args: &Args, res: &mut Resident, options: NormalOptions) {
    let g = grid(n);
    let h = gap(g);
    let a = hertz_radius();
    let pmax = 3.0 * P / (2.0 * std::f64::consts::PI * a * a);
    let prob = NormalProblem {
        tolerance: TOL,
        max_iterations: 10_000,
        options,
        ..NormalProblem::new(&h, P)
    };
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..args.reps(n) {
        let t0 = Instant::now();
        let sol = res.solve_normal(&prob).expect("Hertz solve");
        times.push(t0.elapsed().as_secs_f64());
        last = Some(sol);
    }
    let sol = last.expect("at least one rep");
    let pm = sol.p.iter().cloned().fold(0.0, f64::max);
    let nc = sol.p.iter().filter(|&&v| v > 0.0).count() as f64;
    let radius = (nc * g.cell_area() / std::f64::consts::PI).sqrt();
    let mode = match (options.nested, options.precondition) {
        (true, true) => "nested coarse-to-fine + Fourier-preconditioned PK",
        (true, false) => "nested coarse-to-fine PK",
        (false, true) => "Fourier-preconditioned PK",
        (false, false) => "plain PK",
    };
    println!(
        "{{\"solver\": \"mpcontact\", \"kind\": \"hertz\", \"mode\": \"{mode}\", \"n\": {n}, \"threads\": {}, \"tol\": {TOL:e}, \"iterations\": {}, \"coarse_iterations\": {}, \"applications\": {}, \"seconds\": {:.6}, \"pmax_err\": {:.3e}, \"radius_err\": {:.3e}, \"converged\": {}, \"ok\": true}}",
        args.threads,
        sol.report.iterations,
        sol.report.coarse_iterations,
        sol.report.applications + 1,
        median(times.clone()),
        pm / pmax - 1.0,
        radius / a - 1.0,
        sol.report.converged,
    );
    if !options.nested {
        let in_situ = in_situ_ratio(|| {
            res.solve_normal(&prob).expect("Hertz solve");
        });
        // FFT floor of one fine iteration: the padded transforms of its operator
        // applications, plus (preconditioned) one unpadded periodic pair.
        let pair = fft_pair_seconds(Fft2::new(n), &sol.p, args.reps(n));
        let periodic = fft_pair_seconds(Fft2::periodic(n), &sol.p, args.reps(n));
        let its = sol.report.iterations as f64;
        let apps = (sol.report.applications + 1) as f64;
        let iter_s = median(times) / its;
        let pc = if options.precondition { periodic } else { 0.0 };
        let fft_s = (pair * apps + pc * its) / its;
        println!(
            "{{\"solver\": \"mpcontact\", \"kind\": \"fft_floor\", \"what\": \"normal iteration, {mode}\", \"n\": {n}, \"threads\": {}, \"iter_seconds\": {iter_s:.6}, \"fft_seconds\": {fft_s:.6}, \"applications_per_iteration\": {:.3}, \"fft_pair_seconds\": {pair:.6}, \"ratio\": {:.3}, \"in_situ_ratio\": {}, \"floor_ratio\": {}, \"ok\": true}}",
            args.threads,
            apps / its,
            iter_s / fft_s,
            json_ratio(in_situ.0, args.threads),
            json_ratio(in_situ.1, args.threads)
        );
    }
}

/// A ratio as JSON: `null` when it is not finite or measured with more than
/// one thread (the in-place transform timing sees only the calling thread's
/// share: 2 threads gave 7–37, meaningless, and sometimes `inf`, not JSON).
fn json_ratio(v: f64, threads: usize) -> String {
    if v.is_finite() && threads == 1 {
        format!("{v:.3}")
    } else {
        "null".into()
    }
}

/// A solve's time divided by the time spent in its own transforms, timed in
/// place (`fft2::timing`; with more than one thread only the transforms run
/// on the calling thread are counted, so the ratio means something with one
/// thread only), so the transforms run with the iteration's cache
/// state rather than hot in a loop of their own. The clock reads of the timed
/// spans are calibrated with empty spans and taken out of both times.
///
/// Returns the ratio over the transforms alone and over the transforms plus
/// the operator's spectral products (one read of the kernel spectra per
/// application): the floor of the performance issue #19.
fn in_situ_ratio(mut solve: impl FnMut()) -> (f64, f64) {
    const EMPTY: u64 = 200_000;
    timing::start();
    let t0 = Instant::now();
    for _ in 0..EMPTY {
        drop(std::hint::black_box(timing::Span::new()));
    }
    let outer = t0.elapsed().as_secs_f64() / EMPTY as f64;
    let (inner, _) = timing::stop();
    let inner = inner / EMPTY as f64;
    timing::start();
    let t0 = Instant::now();
    solve();
    let total = t0.elapsed().as_secs_f64();
    let (fft, spans) = timing::stop();
    let (products, product_spans) = timing::products();
    let (spans, product_spans) = (spans as f64, product_spans as f64);
    let solve = total - (spans + product_spans) * outer;
    let fft = fft - spans * inner;
    let floor = fft + products - product_spans * inner;
    (solve / fft, solve / floor)
}

/// Best time of one forward + inverse transform pair (our `Fft2`, with its
/// transposes and zero-padding logic), after a warm-up: the floor.
fn fft_pair_seconds(fft: Fft2, field: &[f64], reps: usize) -> f64 {
    let (fwd, inv) = fft_seconds(fft, field, reps);
    fwd + inv
}

/// Best times of one forward and one inverse transform, after a warm-up.
fn fft_seconds(mut fft: Fft2, field: &[f64], reps: usize) -> (f64, f64) {
    let mut spec = vec![num_complex::Complex64::default(); fft.spectrum_len()];
    let mut out = vec![0.0; field.len()];
    let (mut fwd, mut inv) = (f64::INFINITY, f64::INFINITY);
    for k in 0..(10 * reps).max(10) + 2 {
        let t0 = Instant::now();
        fft.forward_padded(field, &mut spec);
        let t1 = Instant::now();
        fft.inverse_cropped(&mut spec, &mut out);
        if k >= 2 {
            fwd = fwd.min((t1 - t0).as_secs_f64());
            inv = inv.min(t1.elapsed().as_secs_f64());
        }
    }
    (fwd, inv)
}

fn slip(n: usize, args: &Args, threads: &Threads, coupling: bool) {
    let a = hertz_radius();
    let spec = CaseSpec {
        material: Material::isotropic("Fe", E, NU).expect("valid"),
        surface: Surface::Flat,
        grid: Grid::square(n, 4.5 * a / n as f64),
        load: Load {
            indenter_radius_m: R,
            normal_force_n: P,
            friction: MU,
            tangential_ratio: 0.6,
            angle_deg: 0.0,
        },
        numerics: Numerics {
            coupling,
            tolerance: TOL,
            tangential_tolerance: 1e-6,
            max_iterations: 20_000,
            coupling_tolerance: 1e-8,
            max_coupling_iterations: 50,
            ..Numerics::default()
        },
        history: None,
        indenter: None,
    };
    let mut cache = KernelCache::new();
    cache.set_threads(threads.clone());
    let _ = cache.resident(&spec).expect("kernel");
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..args.reps {
        let out = solve_case(&spec, &mut cache).expect("slip solve");
        times.push(out.scalars.seconds);
        last = Some(out);
    }
    let out = last.expect("at least one rep");
    if !coupling {
        // FFT floor of one tangential CG iteration: a cold tangential solve at
        // the final pressure; each application is two padded pairs, each
        // energy product two padded forward transforms.
        let (res, _) = cache.resident(&spec).expect("kernel");
        let force = spec.tangential_force();
        let prob = TangentialProblem {
            p: &out.fields.p,
            friction: MU,
            force,
            extra: None,
            tolerance: 1e-6,
            slip_floor: 0.0,
            max_iterations: 20_000,
            start: TangentialStart::Proportional,
            precondition: false,
            method: Default::default(),
        };
        let in_situ = in_situ_ratio(|| {
            res.solve_tangential(&prob).expect("tangential solve");
        });
        let mut ts = Vec::new();
        let mut rep = None;
        for _ in 0..args.reps {
            let t0 = Instant::now();
            let sol = res.solve_tangential(&prob).expect("tangential solve");
            ts.push(t0.elapsed().as_secs_f64());
            rep = Some(sol.report);
        }
        let rep = rep.expect("at least one rep");
        // The iteration runs on the contact window's grid, when there is one.
        let nw = res.windows.side().unwrap_or(n);
        let pw = match contact_window(n, &out.fields.p) {
            Some(w) if w.n == nw => w.gather(&out.fields.p),
            _ => out.fields.p.clone(),
        };
        let (fwd, inv) = fft_seconds(Fft2::new(nw), &pw, args.reps);
        let pair = fwd + inv;
        let its = rep.iterations as f64;
        // The final slip field comes from the CG phase when it converged.
        let apps = (rep.applications + usize::from(!rep.converged)) as f64;
        let iter_s = median(ts) / its;
        let fft_s = (2.0 * pair * apps + 2.0 * fwd * rep.energy_products as f64) / its;
        println!(
            "{{\"solver\": \"mpcontact\", \"kind\": \"fft_floor\", \"what\": \"tangential CG iteration (Cattaneo-Mindlin)\", \"n\": {n}, \"window\": {nw}, \"threads\": {}, \"iterations\": {}, \"cg_iterations\": {}, \"iter_seconds\": {iter_s:.6}, \"fft_seconds\": {fft_s:.6}, \"applications_per_iteration\": {:.3}, \"energy_products_per_iteration\": {:.3}, \"fft_pair_seconds\": {pair:.6}, \"ratio\": {:.3}, \"in_situ_ratio\": {}, \"floor_ratio\": {}, \"ok\": true}}",
            args.threads,
            rep.iterations,
            rep.cg_iterations,
            apps / its,
            rep.energy_products as f64 / its,
            iter_s / fft_s,
            json_ratio(in_situ.0, args.threads),
            json_ratio(in_situ.1, args.threads)
        );
    }
    let s = &out.scalars;
    let da = spec.grid.cell_area();
    let contact = out.fields.p.iter().filter(|&&v| v > 0.0).count() as f64 * da;
    let stick = out.fields.stick.iter().filter(|&&v| v > 0.5).count() as f64 * da;
    let ca = (stick / contact).sqrt();
    let exact = (1.0_f64 - 0.6).cbrt();
    println!(
        "{{\"solver\": \"mpcontact\", \"kind\": \"slip\", \"mode\": \"{}\", \"n\": {n}, \"threads\": {}, \"tol\": 1e-6, \"iterations\": {}, \"normal_iterations\": {}, \"coupling_iterations\": {}, \"seconds\": {:.6}, \"c_over_a\": {ca:.5}, \"c_over_a_err\": {:.3e}, \"converged\": {}, \"ok\": true}}",
        if coupling { "coupled (normal-tangential)" } else { "uncoupled (Cattaneo-Mindlin)" },
        args.threads,
        s.tangential_iterations,
        s.normal_iterations,
        s.coupling_iterations,
        median(times),
        ca / exact - 1.0,
        s.converged,
    );
}

fn main() {
    let args = match parse() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("compare_hertz: {e}");
            std::process::exit(2);
        }
    };
    let material = Material::isotropic("Fe", E, NU).expect("valid material");
    let threads = match Threads::new(args.threads) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("compare_hertz: {e}");
            std::process::exit(2);
        }
    };
    for &n in &args.sizes {
        let g = grid(n);
        let mut res = Resident::new(build_operator(&material, g));
        res.set_threads(&threads);
        let modes: &[(bool, bool)] = if n >= args.headline_from {
            &[(true, true)]
        } else {
            &[(true, true), (false, true), (false, false)]
        };
        for &(nested, precondition) in modes {
            let options = NormalOptions {
                nested,
                precondition,
            };
            hertz(n, &args, &mut res, options);
        }
    }
    for &n in &args.slip_sizes {
        slip(n, &args, &threads, false);
        slip(n, &args, &threads, true);
    }
}
