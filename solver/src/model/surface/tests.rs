//! The surfaces' tests: patterns against their closed-form covers and
//! reaches, lattices, scans and resampling.

use super::*;

/// The terrain a case reads is the surface's heights and cover, to the
/// bit, for every kind of surface and sampling.
#[test]
fn the_terrain_is_the_heights_and_the_cover() {
    let grid = Grid {
        n: 96,
        dx: 1.3e-6,
        dy: 1.3e-6,
    };
    let circle = |sampling, height| Surface::Lattice {
        island: Island::Circle { diameter: 23e-6 },
        pitch: 41e-6,
        height,
        offset: [2e-6, -5e-6],
        lattice: LatticeKind::Hexagonal,
        sampling,
    };
    let stripes = |sampling| Surface::Stripes {
        width: 9e-6,
        pitch: 25e-6,
        height: 0.5e-6,
        angle_deg: 30.0,
        offset: 1e-6,
        sampling,
    };
    let surfaces = [
        Surface::Flat,
        circle(Sampling::Area, 1e-6),
        circle(Sampling::Area, -1e-6),
        circle(Sampling::Centre, 1e-6),
        stripes(Sampling::Area),
        stripes(Sampling::Centre),
    ];
    let mut cut = 0;
    for s in &surfaces {
        let t = s.terrain(&grid);
        assert_eq!(t.heights, s.heights(&grid), "{s:?}");
        assert_eq!(t.cover, s.cover(&grid), "{s:?}");
        cut += usize::from(t.cover.is_some());
    }
    assert_eq!(cut, 3, "the area-sampled patterns have cut cells");
}

#[test]
fn sampled_coverage_matches_the_analytic_density() {
    let grid = Grid {
        n: 400,
        dx: 1.0e-6,
        dy: 1.0e-6,
    };
    let surfaces = [
        Surface::Lattice {
            island: Island::Circle { diameter: 30e-6 },
            pitch: 50e-6,
            height: 1e-6,
            offset: [3e-6, -7e-6],
            lattice: LatticeKind::Square,
            sampling: Sampling::Centre,
        },
        Surface::Lattice {
            island: Island::Square { side: 20e-6 },
            pitch: 40e-6,
            height: -1e-6,
            offset: [0.0, 0.0],
            lattice: LatticeKind::Square,
            sampling: Sampling::Centre,
        },
        Surface::Lattice {
            island: Island::Circle { diameter: 30e-6 },
            pitch: 50e-6,
            height: 1e-6,
            offset: [0.0, 0.0],
            lattice: LatticeKind::Hexagonal,
            sampling: Sampling::Centre,
        },
        Surface::Stripes {
            width: 10e-6,
            pitch: 40e-6,
            height: 1e-6,
            angle_deg: 30.0,
            offset: 0.0,
            sampling: Sampling::Centre,
        },
    ];
    for s in &surfaces {
        s.validate(grid.n).unwrap();
        let h = s.heights(&grid);
        let covered = h.iter().filter(|&&v| v != 0.0).count() as f64 / grid.len() as f64;
        assert!(
            (covered - s.density()).abs() < 0.01,
            "{s:?}: {covered} vs {}",
            s.density()
        );
    }
}

/// The exact cover sums to the pattern's density: to round-off over a
/// whole number of square-lattice periods, within the part-period
/// border otherwise; the centre sampling of the same grid does not.
#[test]
fn area_sampling_covers_exactly_the_patterns_area() {
    let grid = Grid {
        n: 400,
        dx: 1.3e-6,
        dy: 1.3e-6,
    };
    // 400 cells of 1.3 µm = 520 µm: 8 periods of 65 µm.
    let circle = Surface::Lattice {
        island: Island::Circle { diameter: 41e-6 },
        pitch: 65e-6,
        height: 1e-6,
        offset: [3.1e-6, -7.7e-6],
        lattice: LatticeKind::Square,
        sampling: Sampling::Area,
    };
    let dimples = Surface::Lattice {
        island: Island::Square { side: 27.3e-6 },
        pitch: 65e-6,
        height: -1e-6,
        offset: [0.4e-6, 0.0],
        lattice: LatticeKind::Square,
        sampling: Sampling::Area,
    };
    for s in [&circle, &dimples] {
        let f = s.raised_fraction(&grid);
        let mean = f.iter().sum::<f64>() / grid.len() as f64;
        assert!((mean / s.density() - 1.0).abs() < 1e-12, "{s:?}: {mean}");
    }
    let hex = Surface::Lattice {
        island: Island::Circle { diameter: 30e-6 },
        pitch: 50e-6,
        height: 1e-6,
        offset: [0.0, 0.0],
        lattice: LatticeKind::Hexagonal,
        sampling: Sampling::Area,
    };
    let ridges = Surface::Stripes {
        width: 10e-6,
        pitch: 40e-6,
        height: 1e-6,
        angle_deg: 30.0,
        offset: 2.0e-6,
        sampling: Sampling::Area,
    };
    for s in [&hex, &ridges] {
        let f = s.raised_fraction(&grid);
        let mean = f.iter().sum::<f64>() / grid.len() as f64;
        assert!((mean / s.density() - 1.0).abs() < 0.02, "{s:?}: {mean}");
    }
    // Heights and cover agree: a cut cell is raised (islands) or at the
    // base (dimples) and its cover is its upper part's fraction.
    let (h, c) = (circle.heights(&grid), circle.cover(&grid).unwrap());
    let f = circle.raised_fraction(&grid);
    for i in 0..grid.len() {
        if f[i] >= MIN_COVER {
            assert_eq!(h[i], 1e-6);
            assert!(f[i] == 1.0 || c[i] == f[i]);
        } else {
            assert_eq!((h[i], c[i]), (0.0, 1.0));
        }
    }
    let (h, c) = (dimples.heights(&grid), dimples.cover(&grid).unwrap());
    let f = dimples.raised_fraction(&grid);
    for i in 0..grid.len() {
        if 1.0 - f[i] >= MIN_COVER {
            assert_eq!(h[i], 0.0);
            assert!(f[i] == 0.0 || (c[i] - (1.0 - f[i])).abs() < 1e-15);
        } else {
            assert_eq!((h[i], c[i]), (-1e-6, 1.0));
        }
    }
    // Centre sampling has no cut cells.
    let mut centre = circle.clone();
    if let Surface::Lattice { sampling, .. } = &mut centre {
        *sampling = Sampling::Centre;
    }
    assert!(centre.cover(&grid).is_none());
}

#[test]
fn hexagonal_sites_are_one_pitch_apart_in_six_directions() {
    let p = 10.0;
    for k in 0..6 {
        let a = (k as f64 * 60.0).to_radians();
        let (u, v) = nearest_centre_offset(
            LatticeKind::Hexagonal,
            p,
            p * a.cos() + 0.3,
            p * a.sin() - 0.2,
        );
        assert!(
            (u - 0.3).abs() < 1e-12 && (v + 0.2).abs() < 1e-12,
            "{k}: {u} {v}"
        );
    }
}

/// A small deterministic generator of uniform numbers in [0, 1).
struct Uniform(u64);

impl Uniform {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A `w × h` rectangle whose corner lies anywhere within 30 periods
    /// `(px, py)` of the origin either way.
    fn rect(&mut self, w: f64, h: f64, (px, py): (f64, f64)) -> Rect {
        let x0 = (self.next() - 0.5) * 60.0 * px;
        let y0 = (self.next() - 0.5) * 60.0 * py;
        Rect {
            x0,
            x1: x0 + w,
            y0,
            y1: y0 + h,
        }
    }
}

/// #47: the cover of a cell spanning whole periods of the pattern,
/// integrated period by period in closed form, is the direct sum over
/// every island or ridge in the cell (the sum of before #47, kept as
/// the oracle) to round-off, at 1 to 20 periods per cell, random
/// positions and proportions, both lattices, circles and squares, and
/// ridges at several angles.
#[test]
fn issue47_tiled_cover_is_the_direct_sum_at_1_to_20_periods_per_cell() {
    let mut rng = Uniform(47);
    let pitch = 7.3e-6;
    let mut worst: f64 = 0.0;
    let mut cells = 0;
    for lattice in [LatticeKind::Square, LatticeKind::Hexagonal] {
        let (px, py, _) = supercell(lattice, pitch);
        for shape in 0..2 {
            for _ in 0..150 {
                // The largest island that fits: a diameter or a
                // diagonal of one pitch (Surface::validate).
                let size = (0.2 + 0.75 * rng.next()) * pitch;
                let island = if shape == 0 {
                    Island::Circle { diameter: size }
                } else {
                    Island::Square {
                        side: size * std::f64::consts::FRAC_1_SQRT_2,
                    }
                };
                let offset = [(rng.next() - 0.5) * pitch, (rng.next() - 0.5) * pitch];
                let sites = Sites::new(island, lattice, pitch, offset);
                // 1 to 20 periods one way, 0 to 20 the other.
                let mut span = [(1.0 + 20.0 * rng.next()).min(20.0), 20.0 * rng.next()];
                if rng.next() < 0.5 {
                    span.swap(0, 1);
                }
                let rect = rng.rect(span[0] * px, span[1] * py, (px, py));
                let tiled = sites.area_in(&rect);
                let direct = sites.area_direct(&rect);
                worst = worst.max((tiled - direct).abs() / rect.area());
                cells += 1;
            }
        }
    }
    for angle_deg in [0.0, 17.0, 30.0, 45.0, 60.0, 90.0, 123.4, -71.0, 180.0] {
        let (s, c) = f64::to_radians(angle_deg).sin_cos();
        for _ in 0..150 {
            let ridges = Ridges {
                nx: -s,
                ny: c,
                offset: (rng.next() - 0.5) * pitch,
                width: (0.05 + 0.9 * rng.next()) * pitch,
                pitch,
            };
            let (w, h) = (
                (0.5 + 20.0 * rng.next()) * pitch,
                (0.5 + 20.0 * rng.next()) * pitch,
            );
            let rect = rng.rect(w, h, (pitch, pitch));
            let d = ridges.nx * 0.5 * (rect.x0 + rect.x1) + ridges.ny * 0.5 * (rect.y0 + rect.y1)
                - ridges.offset;
            let spread = 0.5 * (w * s.abs() + h * c.abs());
            let tiled = ridges.area_in(&rect, d, spread);
            let direct = ridges.area_direct(&rect, d, spread);
            worst = worst.max((tiled - direct).abs() / rect.area());
            cells += 1;
        }
    }
    println!("{cells} cells: largest |tiled - direct| / cell area = {worst:.2e}");
    assert!(worst < 1e-12, "{worst:e}");
}

/// #47: a pattern a million times finer than the grid (10¹² islands
/// per cell) costs a handful of sites per cell: every cell's cover is
/// the pattern's density to within one period's share of the cell,
/// the cells add up to the whole domain's area integrated at once, and
/// the mean cover over the grid is the density to within the
/// domain's part-period border (a whole number of periods: to 1e-9).
#[test]
fn issue47_a_pattern_a_million_times_finer_than_the_grid_has_its_density_as_cover() {
    let cell = 1.7e-6;
    let pitch = 1e-6 * cell;
    let grid = Grid::square(48, cell);
    let lattice = |island, lattice, height| Surface::Lattice {
        island,
        pitch,
        height,
        offset: [0.31 * pitch, -0.17 * pitch],
        lattice,
        sampling: Sampling::Area,
    };
    let stripes = |angle_deg| Surface::Stripes {
        width: 0.37 * pitch,
        pitch,
        height: 1e-6,
        angle_deg,
        offset: 0.21 * pitch,
        sampling: Sampling::Area,
    };
    let circle = Island::Circle {
        diameter: 0.6 * pitch,
    };
    let square = Island::Square { side: 0.5 * pitch };
    let surfaces = [
        lattice(circle, LatticeKind::Square, 1e-6),
        lattice(square, LatticeKind::Square, -1e-6),
        lattice(circle, LatticeKind::Hexagonal, 1e-6),
        lattice(square, LatticeKind::Hexagonal, 1e-6),
        stripes(0.0),
        stripes(90.0),
        stripes(30.0),
        stripes(-47.0),
    ];
    let side = grid.n as f64 * cell;
    let domain = Rect::square(0.0, 0.0, side);
    for s in &surfaces {
        s.validate(grid.n).unwrap();
        let f = s.raised_fraction(&grid);
        let rho = s.density();
        let whole = match s {
            Surface::Lattice {
                island,
                lattice,
                offset,
                ..
            } => Sites::new(*island, *lattice, pitch, *offset).area_in(&domain),
            Surface::Stripes {
                width,
                angle_deg,
                offset,
                ..
            } => {
                let (sn, cs) = angle_deg.to_radians().sin_cos();
                let ridges = Ridges {
                    nx: -sn,
                    ny: cs,
                    offset: *offset,
                    width: *width,
                    pitch,
                };
                ridges.area_in(&domain, -ridges.offset, 0.5 * side * (sn.abs() + cs.abs()))
            }
            _ => unreachable!(),
        } / domain.area();
        let mean = f.iter().sum::<f64>() / grid.len() as f64;
        let spread = f.iter().fold(0.0f64, |m, v| m.max((v - rho).abs()));
        let (px, py) = match s {
            Surface::Lattice { lattice, .. } => {
                let (px, py, _) = supercell(*lattice, pitch);
                (px, py)
            }
            _ => (pitch, pitch),
        };
        println!(
            "{s:?}\n  density {rho:.12}, mean cover {mean:.12} ({:.1e}), whole domain {:.1e}, cells within {spread:.1e}",
            mean / rho - 1.0,
            mean / whole - 1.0
        );
        assert!(
            (mean / whole - 1.0).abs() < 1e-12,
            "additivity: {mean} {whole}"
        );
        assert!(spread < 4.0 * (px + py) / cell, "{spread:e}");
        let border = 2.0 * (px + py) / side;
        assert!(
            (mean / rho - 1.0).abs() < border.max(1e-9),
            "{mean} vs {rho}"
        );
    }
    // A whole number of periods: the mean is the density to 1e-9.
    let exact = Surface::Lattice {
        island: circle,
        pitch: cell / 1048576.0,
        height: 1e-6,
        offset: [0.0, 0.0],
        lattice: LatticeKind::Square,
        sampling: Sampling::Area,
    };
    let f = exact.raised_fraction(&grid);
    let mean = f.iter().sum::<f64>() / grid.len() as f64;
    println!(
        "2^20 periods per cell: mean / density - 1 = {:.1e}",
        mean / exact.density() - 1.0
    );
    assert!((mean / exact.density() - 1.0).abs() < 1e-9);
    // The heights and the cover of such a pattern: raised cells, each
    // cut to the density.
    let t = surfaces[0].terrain(&grid);
    assert!(t.heights.iter().all(|&h| h == 1e-6));
    let cover = t.cover.unwrap();
    assert!(cover
        .iter()
        .all(|c| (c - surfaces[0].density()).abs() < 1e-6));
}

/// #47: a grid with fewer than two cells per pitch is told apart from
/// the paper's patterns (many cells per pitch), and the note names the
/// pitch, the ratio, the cell and what the sampling makes of it.
#[test]
fn issue47_an_unresolved_pattern_is_named_with_its_ratio() {
    let grid = Grid::square(128, 2e-6);
    for (name, s) in crate::model::presets::surfaces() {
        assert_eq!(s.unresolved_pattern(&grid), None, "{name}");
    }
    let fine = Surface::Lattice {
        island: Island::Circle { diameter: 1e-12 },
        pitch: 2e-12,
        height: 1e-6,
        offset: [0.0, 0.0],
        lattice: LatticeKind::Square,
        sampling: Sampling::Area,
    };
    assert_eq!(fine.cells_per_pitch(&grid), Some(1e-6));
    let note = fine.unresolved_pattern(&grid).unwrap();
    println!("{note}");
    assert!(
        note.contains("pitch 2.000e-6 µm is 1.000e-6 cells of 2 µm")
            && note.contains("0.196 on average")
            && note.contains("islands"),
        "{note}"
    );
    let mut centre = fine.clone();
    if let Surface::Lattice { sampling, .. } = &mut centre {
        *sampling = Sampling::Centre;
    }
    assert!(centre
        .unresolved_pattern(&grid)
        .unwrap()
        .contains("aliased"));
    assert_eq!(Surface::Flat.unresolved_pattern(&grid), None);
}

#[test]
fn impossible_patterns_are_refused_with_their_field() {
    let bad = [
        (
            Surface::Lattice {
                island: Island::Square { side: 40e-6 },
                pitch: 50e-6,
                height: 1e-6,
                offset: [0.0, 0.0],
                lattice: LatticeKind::Hexagonal,
                sampling: Sampling::Area,
            },
            "side",
        ),
        (
            Surface::Stripes {
                width: 50e-6,
                pitch: 40e-6,
                height: 1e-6,
                angle_deg: 0.0,
                offset: 0.0,
                sampling: Sampling::Area,
            },
            "width",
        ),
        (
            Surface::Heightmap {
                n: 8,
                heights: vec![0.0; 64].into(),
            },
            "heights",
        ),
        (
            Surface::Heightmap {
                n: 16,
                heights: {
                    let mut v = vec![0.0; 256];
                    v[17] = f64::NAN;
                    v.into()
                },
            },
            "heights",
        ),
    ];
    for (s, field) in bad {
        match s.validate(16) {
            Err(SolverError::Invalid { field: f, .. }) => assert_eq!(f, field),
            other => panic!("{s:?}: {other:?}"),
        }
    }
}
