//! Rough boundaries (the constructed cases of `tests/data/rough-cases.gpkg`,
//! made by `scripts/make_rough_cases.py`, and a generated rough polygon):
//! a slot or a spike in a river bank gives no spur, a crescent keeps both
//! horns, and the roughness of a rim leaves no thicket of legs.
#![cfg(all(feature = "cli", feature = "gdal"))]

use crate::common::*;
use geo::{Coord, LineString, MultiLineString, Polygon};
use skeletonise::geometry::PreparedPolygon;
use skeletonise::graph::prune::{prune, PruneParams};
use skeletonise::graph::SkeletonGraph;
use skeletonise::methods::{build, MethodContext, MethodId, SkeletonParams};
use skeletonise::score::defects::{end_turns, HOOK_DEG};
use std::path::Path;

const CASES: &str = "tests/data/rough-cases.gpkg";

/// Runs the default pipeline on the cases (with `--set` overrides) and
/// returns each case's skeleton lines, in FID order.
fn run_cases(dir: &Path, sets: &[&str]) -> Vec<MultiLineString<f64>> {
    let out = dir.join("out.gpkg");
    let text = format!(
        "input: {{ source: {}, layer: cases }}\nsteps:\n  - prepare: {{}}\n  - skeleton: {{}}\n  - prune: {{}}\n  - extend: {{}}\n  - score: {{}}\n  - select: {{}}\noutput: {{ path: {}, overwrite: true }}\n",
        root(CASES),
        out.display()
    );
    let p = pipeline(dir, "p.yaml", &text);
    let mut args = vec!["run", p.to_str().unwrap()];
    for s in sets {
        args.extend(["--set", s]);
    }
    let o = skeletonise(&args);
    assert!(o.status.success(), "{}", code_and_err(&o).1);
    let ds = open(&out);
    wkts(&ds, "skeletons")
        .into_iter()
        .map(|w| {
            let g: geo::Geometry<f64> =
                wkt::TryFromWkt::try_from_wkt_str(&w.expect("a skeleton")).unwrap();
            match g {
                geo::Geometry::MultiLineString(m) => m,
                geo::Geometry::LineString(l) => MultiLineString(vec![l]),
                other => panic!("not lines: {other:?}"),
            }
        })
        .collect()
}

/// The case polygons, in FID order.
fn cases() -> Vec<PreparedPolygon> {
    let ds = open(Path::new(&root(CASES)));
    wkts(&ds, "cases")
        .into_iter()
        .map(|w| {
            let p: Polygon<f64> = wkt::TryFromWkt::try_from_wkt_str(&w.unwrap()).unwrap();
            PreparedPolygon::new(&p).unwrap()
        })
        .collect()
}

fn near(lines: &MultiLineString<f64>, p: Coord<f64>, d: f64) -> bool {
    lines
        .0
        .iter()
        .flat_map(|l| l.0.iter())
        .any(|q| (q.x - p.x).hypot(q.y - p.y) < d)
}

#[test]
fn a_slot_and_a_spike_in_a_river_bank_give_no_spur_and_no_hook() {
    let dir = tmp();
    let polys = cases();
    let river = &polys[0];
    // The slot's and the spike's far ends (see make_rough_cases.py).
    let ring = &river.polygon().exterior().0;
    // The far end: of the vertices at this easting, the one farthest from
    // the river's centre line (y = 6 000 000 + 600 cos(…)).
    let vertex_at = |x: f64| {
        *ring
            .iter()
            .filter(|c| (c.x - x).abs() < 0.01)
            .max_by(|a, b| {
                (a.y - 6_000_000.0)
                    .abs()
                    .total_cmp(&(b.y - 6_000_000.0).abs())
            })
            .expect("the case's vertex")
    };
    let (slot, spike) = (vertex_at(504_001.0), vertex_at(508_002.0));
    assert!(slot.y > spike.y + 1000.0);
    let lines = &run_cases(dir.path(), &[])[0];
    assert_eq!(
        leaves(lines).len(),
        2,
        "one line from end to end: {lines:?}"
    );
    assert!(!near(lines, slot, 150.0), "a spur into the slot");
    assert!(!near(lines, spike, 150.0), "a spur into the spike");
    let g = SkeletonGraph::from_lines(lines);
    let turns = end_turns(&g, river);
    assert!(turns.iter().all(|&t| t <= HOOK_DEG), "hooks: {turns:?}");
    // Without the width condition of an arm, both come back as spurs.
    let old = &run_cases(dir.path(), &["steps.prune.arm_width=0"])[0];
    assert!(near(old, slot, 150.0) && near(old, spike, 150.0));
}

/// A compact lake (a disc cut flat on its east side) with a tip to the
/// south: its line runs into the tip, not to the middle of the broad east
/// shore, and has no hooked end.
#[test]
fn a_compact_lake_reaches_its_tip_not_its_side_shore() {
    let dir = tmp();
    let lines = &run_cases(dir.path(), &[])[1];
    // make_rough_cases.py: the disc's centre at (510 000, 6 020 000), the
    // tip's end 4.3 km south, the flat shore at x = +1.6 km from y = -1.2 to
    // +1.2 km.
    let tip = Coord {
        x: 510_000.0,
        y: 6_015_700.0,
    };
    let side = Coord {
        x: 511_600.0,
        y: 6_020_000.0,
    };
    let ends = leaves(lines);
    assert_eq!(ends.len(), 2, "{ends:?}");
    let d = |a: Coord<f64>, b: Coord<f64>| (a.x - b.x).hypot(a.y - b.y);
    assert!(
        ends.iter().any(|&e| d(e, tip) < 60.0),
        "no end in the tip: {ends:?}"
    );
    assert!(
        ends.iter().all(|&e| d(e, side) > 800.0),
        "an end on the middle of the east shore: {ends:?}"
    );
    let g = SkeletonGraph::from_lines(lines);
    let turns = end_turns(&g, &cases()[1]);
    assert!(turns.iter().all(|&t| t <= HOOK_DEG), "hooks: {turns:?}");
}

#[test]
fn a_crescent_keeps_both_horns() {
    let dir = tmp();
    let lines = &run_cases(dir.path(), &[])[2];
    // The horns: where the circles of radius 3 000 (centre 0, 0) and 2 500
    // (centre 1 400, 0) meet, moved as in make_rough_cases.py.
    let x = (3000f64.powi(2) - 2500f64.powi(2) + 1400f64.powi(2)) / 2800.0;
    let y = (3000f64.powi(2) - x * x).sqrt();
    let ends = leaves(lines);
    assert_eq!(ends.len(), 2);
    for horn in [
        Coord {
            x: 520_000.0 + x,
            y: 6_020_000.0 + y,
        },
        Coord {
            x: 520_000.0 + x,
            y: 6_020_000.0 - y,
        },
    ] {
        assert!(
            ends.iter()
                .any(|e| (e.x - horn.x).hypot(e.y - horn.y) < 60.0),
            "no end at the horn {horn:?}: {ends:?}"
        );
    }
}

/// The direction of the line `lines` over its last `len` at the end nearest
/// `p`, pointing out of the line, and that end.
fn end_course(lines: &MultiLineString<f64>, p: Coord<f64>, len: f64) -> (Coord<f64>, Coord<f64>) {
    let d = |a: Coord<f64>, b: Coord<f64>| (a.x - b.x).hypot(a.y - b.y);
    let line = lines
        .0
        .iter()
        .map(|l| {
            let mut c = l.0.clone();
            if d(c[0], p) > d(*c.last().unwrap(), p) {
                c.reverse();
            }
            c
        })
        .min_by(|a, b| d(a[0], p).total_cmp(&d(b[0], p)))
        .expect("a line");
    let end = line[0];
    let mut walked = 0.0;
    let mut back = end;
    for w in line.windows(2) {
        let step = d(w[0], w[1]);
        if walked + step >= len {
            let t = (len - walked) / step;
            back = Coord {
                x: w[0].x + (w[1].x - w[0].x) * t,
                y: w[0].y + (w[1].y - w[0].y) * t,
            };
            break;
        }
        walked += step;
        back = w[1];
    }
    let n = d(end, back);
    (
        Coord {
            x: (end.x - back.x) / n,
            y: (end.y - back.y) / n,
        },
        end,
    )
}

/// A compact lake with one real lobe and 96 shallow bank vertices on its
/// broad shore: one end of its line lies in the lobe's end, reached along
/// the lobe's axis; no end is a hook.
#[test]
fn a_compact_lake_with_one_lobe_ends_in_the_lobe_along_its_axis() {
    let dir = tmp();
    let lines = &run_cases(dir.path(), &[])[3];
    // make_rough_cases.py: the disc's centre at (530 000, 6 020 000), the
    // lobe along the north-east diagonal, its end 3.6 km from the centre.
    let s = 3600.0 / 2f64.sqrt();
    let lobe_end = Coord {
        x: 530_000.0 + s,
        y: 6_020_000.0 + s,
    };
    let ends = leaves(lines);
    assert_eq!(ends.len(), 2, "{ends:?}");
    let d = |a: Coord<f64>, b: Coord<f64>| (a.x - b.x).hypot(a.y - b.y);
    assert!(
        ends.iter().any(|&e| d(e, lobe_end) < 60.0),
        "no end in the lobe's end: {ends:?}"
    );
    // Over the lobe's last 700 m (its width) the line runs along its axis.
    let (course, _) = end_course(lines, lobe_end, 700.0);
    let axis = 0.5f64.sqrt();
    let cos = course.x * axis + course.y * axis;
    assert!(
        cos > 30f64.to_radians().cos(),
        "the end leaves the lobe's axis: {course:?}"
    );
    let g = SkeletonGraph::from_lines(lines);
    let turns = end_turns(&g, &cases()[3]);
    assert!(turns.iter().all(|&t| t <= HOOK_DEG), "hooks: {turns:?}");
}

/// A near-square island with one sharp corner (about 30°): its line ends
/// in that corner.
#[test]
fn a_near_square_island_ends_in_its_sharp_corner() {
    let dir = tmp();
    let lines = &run_cases(dir.path(), &[])[4];
    let corner = Coord {
        x: 540_000.0 + 2700.0,
        y: 6_020_000.0 + 2700.0,
    };
    let ends = leaves(lines);
    assert_eq!(ends.len(), 2, "{ends:?}");
    assert!(
        ends.iter()
            .any(|e| (e.x - corner.x).hypot(e.y - corner.y) < 1.0),
        "no end in the sharp corner: {ends:?}"
    );
    let g = SkeletonGraph::from_lines(lines);
    let turns = end_turns(&g, &cases()[4]);
    assert!(turns.iter().all(|&t| t <= HOOK_DEG), "hooks: {turns:?}");
}

/// A five-lobed polygon of radius `radius` with up to `rough` of random
/// radial roughness at each of `n` vertices (scripts/make_rough_polygon.py's
/// shape, with a small seeded generator of its own).
fn rough_lobes(n: usize, radius: f64, rough: f64) -> PreparedPolygon {
    let mut state: u64 = 20_261_205;
    let mut uniform = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let ring: Vec<Coord<f64>> = (0..n)
        .map(|i| {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            let r = radius * (1.0 + 0.3 * (5.0 * t).sin()) + rough * uniform();
            Coord {
                x: r * t.cos(),
                y: r * t.sin(),
            }
        })
        .collect();
    PreparedPolygon::new(&Polygon::new(LineString::new(ring), vec![])).unwrap()
}

/// The medial axis of `p`.
fn medial_axis(p: &PreparedPolygon) -> SkeletonGraph {
    let params = SkeletonParams {
        methods: vec![MethodId::MA],
        ..Default::default()
    };
    build(MethodId::MA, &params)
        .skeletonise(p, &MethodContext::default())
        .unwrap()
}

/// The angle (radians) between the direction of `pos` from the centre of
/// [`rough_lobes`] and the nearest lobe's axis (sin 5t = 1).
fn off_lobe_axes(pos: Coord<f64>) -> f64 {
    let t = pos.y.atan2(pos.x);
    (0..5)
        .map(|k| {
            let axis = std::f64::consts::PI / 10.0 + k as f64 * std::f64::consts::TAU / 5.0;
            let d = (t - axis).rem_euclid(std::f64::consts::TAU);
            d.min(std::f64::consts::TAU - d)
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn the_roughness_of_a_rim_leaves_no_thicket_of_legs() {
    // Radius 10 km, vertices every 0.35 m with up to 30 m of roughness: a
    // rim of needles (the shape of scripts/make_rough_polygon.py at 200 000
    // vertices). Pruned, the medial axis keeps the lobes' structure only —
    // a handful of legs, not one per needle (tens of thousands before sides
    // were judged), and no brush of legs where a line runs into the rim.
    let p = rough_lobes(200_000, 10_000.0, 30.0);
    let ma = medial_axis(&p);
    let pruned = prune(&ma, &PruneParams::default(), p.boundary());
    assert!(ma.leg_count() > 5_000, "{} raw legs", ma.leg_count());
    assert!(pruned.leg_count() <= 10, "{} legs kept", pruned.leg_count());
    // Every kept end lies on a lobe's axis (sin 5t = 1), none in the rim
    // between the lobes, and no two ends lie within 20 m of each other
    // (a brush of legs where a line runs into the rim).
    let g = pruned;
    let deg = g.degrees();
    let ends: Vec<Coord<f64>> = (0..deg.len())
        .filter(|&i| deg[i] == 1)
        .map(|i| g.nodes()[i].pos)
        .collect();
    for (i, a) in ends.iter().enumerate() {
        for b in &ends[i + 1..] {
            assert!(
                (a.x - b.x).hypot(a.y - b.y) > 20.0,
                "a brush of ends at {a:?}"
            );
        }
    }
    for (i, n) in g.nodes().iter().enumerate() {
        if deg[i] == 1 {
            let off = off_lobe_axes(n.pos);
            assert!(
                off < 0.1,
                "an end {:.0}° off the lobes' axes",
                off.to_degrees()
            );
        }
    }
}

/// Runs `cmd` with `args`, which must succeed.
fn must(cmd: &str, args: &[&str]) {
    let o = std::process::Command::new(cmd)
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("{cmd}: {e}"));
    assert!(
        o.status.success(),
        "{cmd} {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// The default pipeline on every method, the candidates written: the
/// output's path.
fn run_all_methods(dir: &Path, name: &str, source: &str, layer: &str) -> std::path::PathBuf {
    let out = dir.join(format!("{name}.gpkg"));
    let text = format!(
        "input: {{ source: {source}, layer: {layer} }}\nsteps:\n  - prepare: {{ make_valid: true }}\n  - skeleton: {{ methods: [MA, StSk, DVD, CDT, VD] }}\n  - prune: {{}}\n  - extend: {{}}\n  - score: {{}}\n  - select: {{}}\noutput: {{ path: {}, overwrite: true, candidates: true }}\n",
        out.display()
    );
    let p = pipeline(dir, &format!("{name}.yaml"), &text);
    let o = skeletonise(&["run", "-q", p.to_str().unwrap()]);
    assert!(o.status.success(), "{}", code_and_err(&o).1);
    out
}

/// Training layer `layer` rasterised at `cell` metres and vectorised again
/// with `gdal_polygonize -8`, as a satellite water mask gives it: the
/// largest piece (the others are pixels cut off at narrows), as layer
/// `raster` of the returned file.
fn rasterise(d: &Path, layer: &str, cell: u32) -> std::path::PathBuf {
    let (tif, poly, raster) = (d.join("r.tif"), d.join("poly.gpkg"), d.join("raster.gpkg"));
    let cell = cell.to_string();
    must(
        "gdal_rasterize",
        &[
            "-q",
            "-burn",
            "1",
            "-tr",
            &cell,
            &cell,
            "-ot",
            "Byte",
            "-a_nodata",
            "0",
            "-l",
            layer,
            &root(TRAIN),
            tif.to_str().unwrap(),
        ],
    );
    must(
        "gdal_polygonize.py",
        &[
            "-q",
            "-8",
            tif.to_str().unwrap(),
            "-f",
            "GPKG",
            poly.to_str().unwrap(),
            "poly",
            "v",
        ],
    );
    must(
        "ogr2ogr",
        &[
            "-f",
            "GPKG",
            raster.to_str().unwrap(),
            poly.to_str().unwrap(),
            "-nln",
            "raster",
            "-sql",
            "SELECT * FROM poly WHERE v = 1 ORDER BY ST_Area(geom) DESC LIMIT 1",
        ],
    );
    raster
}

/// The Danube rasterised at 15 m: every method's line has the medial
/// axis's legs, in one piece. DVD's skeleton falls apart at the channels
/// one or two pixels wide; the leaf nearest two of the tips sat on a crumb
/// beside the skeleton, and DVD lost both arms (3 legs in 3 pieces).
#[test]
fn a_rasterised_river_gives_every_method_the_same_legs_in_one_piece() {
    let dir = tmp();
    let d = dir.path();
    let raster = rasterise(d, "river_danube", 15);
    let ras = run_all_methods(d, "ras", raster.to_str().unwrap(), "raster");
    let ds = open(&ras);
    let methods = strings(&ds, "candidates", "method");
    let legs = ints(&ds, "candidates", "legs");
    let pieces = ints(&ds, "candidates", "components");
    assert_eq!(methods.len(), 5, "{methods:?}");
    let ma = methods
        .iter()
        .position(|m| m.as_deref() == Some("MA"))
        .unwrap();
    for i in 0..methods.len() {
        assert_eq!(
            (legs[i], pieces[i]),
            (legs[ma], Some(1)),
            "{:?}: legs and pieces against MA's",
            methods[i]
        );
    }
}

/// A river rasterised at 30 m and vectorised again with `gdal_polygonize -8`
/// (57 000 vertices, every one a right-angled corner, half of them reflex:
/// a satellite water mask): every method runs — the straight skeleton is
/// neither declined nor failed (its simultaneous events and long split
/// searches made it quadratic) — and the chosen line has the vector river's
/// legs (± 1), is centred (Z ≤ 0.001) and has no hooked end.
#[test]
fn a_rasterised_river_runs_every_method_and_keeps_the_vector_rivers_legs() {
    let dir = tmp();
    let d = dir.path();
    let train = root(TRAIN);
    let layer = "river_st_lawrence";
    let raster = rasterise(d, layer, 30);
    let ras = run_all_methods(d, "ras", raster.to_str().unwrap(), "raster");
    let vec = run_all_methods(d, "vec", &train, layer);
    let ds = open(&ras);
    let methods = strings(&ds, "candidates", "method");
    let errors = strings(&ds, "candidates", "error");
    assert_eq!(methods.len(), 5, "{methods:?}");
    for (m, e) in methods.iter().zip(&errors) {
        assert!(
            e.as_deref().unwrap_or("").is_empty(),
            "{m:?} did not run: {e:?}"
        );
    }
    let legs = ints(&ds, "skeletons", "legs")[0].unwrap();
    let vector_legs = ints(&open(&vec), "skeletons", "legs")[0].unwrap();
    assert!(
        (legs - vector_legs).abs() <= 1,
        "raster {legs} legs, vector {vector_legs}"
    );
    let z = reals(&ds, "skeletons", "distortion")[0].unwrap();
    assert!(z <= 0.001, "Z {z}");
    let lines = &wkts(&ds, "skeletons")[0];
    let g: geo::Geometry<f64> =
        wkt::TryFromWkt::try_from_wkt_str(lines.as_deref().unwrap()).unwrap();
    let g = match g {
        geo::Geometry::MultiLineString(m) => SkeletonGraph::from_lines(&m),
        other => panic!("not lines: {other:?}"),
    };
    let p: Polygon<f64> =
        wkt::TryFromWkt::try_from_wkt_str(wkts(&open(&raster), "raster")[0].as_deref().unwrap())
            .unwrap();
    let turns = end_turns(&g, &PreparedPolygon::new(&p).unwrap());
    assert!(turns.iter().all(|&t| t <= HOOK_DEG), "hooks: {turns:?}");
}

/// A five-lobed star, smooth and rough: its main axis runs from a lobe's
/// tip to another's along the medial axis — never straight on from the
/// centre into the valley between two lobes (the two lobes there forked
/// around the line like the corners of a square end, and the line ended
/// between them, on the shore nearest the centre).
#[test]
fn a_stars_line_runs_from_lobe_tip_to_lobe_tip() {
    use skeletonise::graph::extend::{prune_and_extend, ExtendParams};
    for (n, rough) in [(4_000, 0.0), (20_000, 30.0)] {
        let p = rough_lobes(n, 10_000.0, rough);
        let ma = medial_axis(&p);
        let g = prune_and_extend(
            &ma,
            &p,
            Some(&PruneParams::default()),
            Some(&ExtendParams::default()),
        );
        let deg = g.degrees();
        let ends: Vec<Coord<f64>> = (0..deg.len())
            .filter(|&i| deg[i] == 1)
            .map(|i| g.nodes()[i].pos)
            .collect();
        assert!(ends.len() >= 2, "{n} vertices: {ends:?}");
        for e in &ends {
            // A lobe's tip lies 13 km out on its axis (sin 5t = 1); the
            // valleys 7 km out between them.
            let off = off_lobe_axes(*e);
            let r = e.x.hypot(e.y);
            assert!(
                off < 0.05 && r > 12_500.0,
                "{n} vertices: an end {:.0}° off a lobe's axis, {r:.0} m from the centre",
                off.to_degrees()
            );
        }
    }
}

#[test]
fn the_straight_skeleton_of_a_rough_rim_fits_a_small_memory_budget() {
    use skeletonise::methods::budget::{with_budget, Budget};
    use skeletonise::methods::straight_skeleton::straight_skeleton_with_stats;
    // 50 000 vertices every 1.3 m with up to 30 m of roughness: a rim of
    // needles. Each reflex vertex looks for the wavefront edges it may split
    // along its ray; nearly all of the rim's edges near it have left the
    // wavefront by the time it gets there, and those are no longer looked
    // at. The split events then need about 3 MB (they needed 140 MB when the
    // gone edges were kept), so a `max_memory_mb` of 16 lets it through, in
    // the first, local search pass.
    let p = rough_lobes(50_000, 10_000.0, 30.0);
    let budget = Budget {
        time: None,
        memory: Some(16_000_000),
    };
    let (g, stats) = with_budget(MethodId::STSK, budget, |ctx| {
        straight_skeleton_with_stats(&p, ctx)
    })
    .unwrap_or_else(|e| panic!("declined or failed: {e}"));
    g.check_invariants().unwrap();
    assert_eq!(stats.passes, 1);
    assert!(g.edges().len() > 50_000, "{} edges", g.edges().len());
    assert!(
        stats.candidates < 10 * 50_000,
        "{} split candidates kept",
        stats.candidates
    );
}
