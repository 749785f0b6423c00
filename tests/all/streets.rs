//! Street space to a street network: `prune: { junctions: merge }` gives one
//! node per junction where the street space's medial axis has two three-way
//! nodes and a stub for every four-way crossing, and a small triangle at a
//! skewed or five-arm one. Run through the binary on the generated city
//! quarter of `tests/data/streets.gpkg` (`scripts/make_streets.py`): its
//! streets' own centrelines are the reference.
#![cfg(all(feature = "cli", feature = "gdal"))]

use crate::common::*;
use gdal::vector::LayerAccess;
use geo::{Coord, Distance, Euclidean, Geometry, LineString, MultiLineString, Polygon};
use skeletonise::geometry::PreparedPolygon;
use skeletonise::graph::SkeletonGraph;
use std::path::Path;

const STREETS: &str = "tests/data/streets.gpkg";

/// Every geometry of `layer` in `path`.
fn geometries(path: &Path, layer: &str) -> Vec<Geometry<f64>> {
    let ds = open(path);
    let mut l = ds.layer_by_name(layer).unwrap();
    l.features()
        .map(|f| wkt::TryFromWkt::try_from_wkt_str(&f.geometry().unwrap().wkt().unwrap()).unwrap())
        .collect()
}

fn points(layer: &str) -> Vec<Coord<f64>> {
    geometries(Path::new(&root(STREETS)), layer)
        .into_iter()
        .map(|g| match g {
            Geometry::Point(p) => p.0,
            other => panic!("not a point: {other:?}"),
        })
        .collect()
}

/// The skeleton layer's lines of a run of `layer` with `prune`.
fn run(dir: &Path, layer: &str, prune: &str) -> MultiLineString<f64> {
    let out = dir.join(format!("{layer}{}.gpkg", prune.len()));
    let text = format!(
        "input: {{ source: {}, layer: {layer} }}\nsteps:\n  - skeleton: {{}}\n  - prune: {prune}\n  - extend: {{}}\n  - score: {{}}\n  - select: {{}}\noutput: {{ path: {} }}\n",
        root(STREETS),
        out.display()
    );
    let p = pipeline(dir, "streets.yaml", &text);
    let o = skeletonise(&["run", p.to_str().unwrap(), "-q"]);
    assert_eq!(code_and_err(&o).0, 0, "{}", code_and_err(&o).1);
    let mut lines = Vec::new();
    for g in geometries(&out, "skeletons") {
        match g {
            Geometry::MultiLineString(m) => lines.extend(m.0),
            Geometry::LineString(l) => lines.push(l),
            other => panic!("not lines: {other:?}"),
        }
    }
    MultiLineString(lines)
}

/// The nodes of `lines` of degree ≥ 3, and their line ends.
fn junctions_and_ends(lines: &MultiLineString<f64>) -> (Vec<Coord<f64>>, Vec<Coord<f64>>) {
    let g = SkeletonGraph::from_lines(lines);
    let d = g.degrees();
    let at = |f: fn(usize) -> bool| -> Vec<Coord<f64>> {
        (0..d.len())
            .filter(|&i| f(d[i]))
            .map(|i| g.nodes()[i].pos)
            .collect()
    };
    (at(|x| x >= 3), at(|x| x == 1))
}

/// How the output's junctions match the reference's: for each reference
/// junction, the output junctions within its local width (2r); the output
/// junctions near none; pairs of output junctions closer than the local width.
fn matching(
    space: &PreparedPolygon,
    reference: &[Coord<f64>],
    out: &[Coord<f64>],
) -> (Vec<usize>, usize, usize) {
    let width = |c: Coord<f64>| 2.0 * space.boundary().distance(c);
    let dist = |a: Coord<f64>, b: Coord<f64>| Euclidean.distance(geo::Point(a), geo::Point(b));
    let each = reference
        .iter()
        .map(|&r| out.iter().filter(|&&o| dist(o, r) <= width(r)).count())
        .collect();
    let extra = out
        .iter()
        .filter(|&&o| reference.iter().all(|&r| dist(o, r) > width(r)))
        .count();
    let close = (0..out.len())
        .flat_map(|i| (i + 1..out.len()).map(move |j| (i, j)))
        .filter(|&(i, j)| dist(out[i], out[j]) < width(out[i]).min(width(out[j])))
        .count();
    (each, extra, close)
}

/// Reference junctions with a node of their own when each output node
/// serves at most one (nearest pairs first, within the junction's local
/// width): a node between two junctions serves one of them.
fn one_to_one(space: &PreparedPolygon, reference: &[Coord<f64>], out: &[Coord<f64>]) -> usize {
    let dist = |a: Coord<f64>, b: Coord<f64>| Euclidean.distance(geo::Point(a), geo::Point(b));
    let mut pairs: Vec<(f64, usize, usize)> = reference
        .iter()
        .enumerate()
        .flat_map(|(i, &r)| {
            out.iter()
                .enumerate()
                .map(move |(k, &o)| (dist(o, r), i, k))
        })
        .filter(|&(d, i, _)| d <= 2.0 * space.boundary().distance(reference[i]))
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (mut served, mut used) = (vec![false; reference.len()], vec![false; out.len()]);
    for (_, i, k) in pairs {
        if !served[i] && !used[k] {
            (served[i], used[k]) = (true, true);
        }
    }
    served.iter().filter(|&&s| s).count()
}

/// As many line ends as the reference has, one within the widest street's
/// width (16 m) of each reference end.
fn one_end_each(ends: &[Coord<f64>], reference_ends: &[Coord<f64>]) {
    let near =
        |a: Coord<f64>, b: Coord<f64>| Euclidean.distance(geo::Point(a), geo::Point(b)) <= 16.0;
    assert_eq!(ends.len(), reference_ends.len(), "{ends:?}");
    for r in reference_ends {
        assert_eq!(
            ends.iter().filter(|&&e| near(e, *r)).count(),
            1,
            "{r:?}: {ends:?}"
        );
    }
}

fn space(layer: &str) -> Vec<PreparedPolygon> {
    match geometries(Path::new(&root(STREETS)), layer).remove(0) {
        Geometry::Polygon(p) => vec![PreparedPolygon::new(&p).unwrap()],
        Geometry::MultiPolygon(m) => {
            m.0.iter()
                .map(|p| PreparedPolygon::new(p).unwrap())
                .collect()
        }
        other => panic!("not a polygon: {other:?}"),
    }
}

fn quarter() -> PreparedPolygon {
    space("quarter").remove(0)
}

#[test]
fn merged_junctions_are_the_streets_junctions_one_to_one() {
    let d = tmp();
    let space = quarter();
    let reference = points("quarter_junctions");
    assert_eq!(reference.len(), 12);
    // As before (`keep`): a crossing is two nodes and a stub, a skewed or
    // five-arm one a triangle — several nodes at 4 of the 12 junctions.
    let kept = run(d.path(), "quarter", "{}");
    let (out, _) = junctions_and_ends(&kept);
    let (each, _, close) = matching(&space, &reference, &out);
    assert!(
        each.iter().filter(|&&n| n > 1).count() >= 3 && close > 0,
        "{each:?} {close}"
    );
    // Merged: exactly one node within each junction's local width, none
    // elsewhere, no two closer than the local width.
    let merged = run(d.path(), "quarter", "{ junctions: merge }");
    let (out, ends) = junctions_and_ends(&merged);
    let (each, extra, close) = matching(&space, &reference, &out);
    assert_eq!(each, vec![1; reference.len()], "{out:?}");
    assert_eq!((extra, close), (0, 0), "{out:?}");
    // One line end per reference end (the dead end, the cut ends at the
    // data's edge, which lie on the boundary: no local width there), each
    // within the widest street's width (16 m) of it.
    one_end_each(&ends, &points("quarter_ends"));
    // The straightened lines stay inside the street space.
    let poly: &Polygon<f64> = space.polygon();
    for l in &merged.0 {
        for c in &l.0 {
            assert!(
                geo::Contains::contains(poly, c) || space.boundary().distance(*c) < 1e-6,
                "{c:?} outside the street space"
            );
        }
    }
}

#[test]
fn a_street_cut_by_a_rough_edge_ends_once_on_it() {
    // The quarter cut by a rough edge (a vertex every metre, moved across
    // the edge by up to ±1 m): the medial axis forks into the teeth. Before,
    // only a straight cut ended once, and a fork stayed at one street's
    // end (16 ends for 15); merged, a cut within a fifth of the street's
    // width of a straight line ends once, as a straight one does.
    let d = tmp();
    let space = space("quarter_ragged").remove(0);
    let reference = points("quarter_junctions");
    let reference_ends = points("quarter_ends");
    let merged = run(d.path(), "quarter_ragged", "{ junctions: merge }");
    let (out, ends) = junctions_and_ends(&merged);
    let (each, extra, close) = matching(&space, &reference, &out);
    assert_eq!(each, vec![1; reference.len()], "{out:?}");
    assert_eq!((extra, close), (0, 0), "{out:?}");
    one_end_each(&ends, &reference_ends);
    // Every end lies on the cut (on the street space's boundary).
    for e in &ends {
        assert!(
            space.boundary().distance(*e) < 1e-6,
            "{e:?} short of the cut"
        );
    }
    // Rivers and lakes keep the straight rule: without `merge` the rough
    // cut is no cut, and its fork stays.
    let kept = run(d.path(), "quarter_ragged", "{}");
    let (_, kept_ends) = junctions_and_ends(&kept);
    assert!(kept_ends.len() > reference_ends.len(), "{kept_ends:?}");
}

#[test]
fn on_a_real_network_buffered_as_roads_merged_junctions_match_the_lines_junctions() {
    // The rivers of 8–12° E, 46–50° N (GSHHG/WDBII) scaled to a 15 × 22 km
    // network of 16 m roads: 20 junctions in the lines, two of them where a
    // line crosses itself in a loop narrower than the road (no junction in
    // the road space). Acute forks are most of the rest: there the medial
    // axis forks past the lines' meeting point, beyond the local width.
    let d = tmp();
    let parts = space("roads");
    let reference = points("roads_junctions");
    assert_eq!(reference.len(), 20);
    let count = |prune: &str| {
        let (out, _) = junctions_and_ends(&run(d.path(), "roads", prune));
        // Each junction against the part it lies in.
        let part = |c: Coord<f64>| {
            parts
                .iter()
                .find(|p| p.boundary().contains(c))
                .unwrap_or(&parts[0])
        };
        let width = |c: Coord<f64>| 2.0 * part(c).boundary().distance(c);
        let dist = |a: Coord<f64>, b: Coord<f64>| Euclidean.distance(geo::Point(a), geo::Point(b));
        let one = reference
            .iter()
            .filter(|&&r| out.iter().filter(|&&o| dist(o, r) <= width(r)).count() == 1)
            .count();
        let extra = out
            .iter()
            .filter(|&&o| reference.iter().all(|&r| dist(o, r) > width(r)))
            .count();
        (one, extra)
    };
    let (kept, kept_extra) = count("{}");
    let (merged, merged_extra) = count("{ junctions: merge }");
    // Measured: keep 17 of 20 with one node, 2 nodes with no junction
    // near; merge 18 of 20, 1 (two parallel roads whose spaces merge).
    assert!(merged >= 18 && merged >= kept, "{kept} → {merged}");
    assert!(
        merged_extra <= 1 && merged_extra <= kept_extra,
        "{kept_extra} → {merged_extra}"
    );
}

#[test]
fn between_real_blocks_merged_junctions_are_whole_and_one_each() {
    // Street space between 21 US states of GMT's DCW as blocks (10 m
    // streets, 26 junctions of 3 and 4 arms, borders along rivers as
    // meandering streets): the chosen network is in one piece (DVD's breaks
    // on the long straight borders), and two T-junctions one street apart
    // (a staggered crossing) stay two, each where its streets meet.
    let d = tmp();
    let space = space("states").remove(0);
    let reference = points("states_junctions");
    assert_eq!(reference.len(), 26);
    let count = |prune: &str| {
        let lines = run(d.path(), "states", prune);
        assert_eq!(SkeletonGraph::from_lines(&lines).components(), 1);
        let (out, _) = junctions_and_ends(&lines);
        let (each, extra, _) = matching(&space, &reference, &out);
        let one = each.iter().filter(|&&n| n == 1).count();
        let none = each.iter().filter(|&&n| n == 0).count();
        (one, none, extra, one_to_one(&space, &reference, &out))
    };
    let kept = count("{}");
    let merged = count("{ junctions: merge }");
    // Measured: keep 23 with one node, 3 with two, 1 node near none, 26
    // one to one (28 nodes); merge 24, 2, 1, 26 (27 nodes). The two with
    // two: reference junctions closer to each other than their local width,
    // each with a node of its own.
    assert!(
        merged.0 >= 24 && merged.0 >= kept.0,
        "{kept:?} → {merged:?}"
    );
    assert_eq!(merged.1, 0, "{merged:?}");
    assert!(merged.2 <= 1, "{merged:?}");
    assert_eq!(merged.3, 26, "{merged:?}");
}

/// A row of the `streets` layer: line, start and end degree, left and right FID.
type Piece = (LineString<f64>, i64, i64, Option<i64>, Option<i64>);

#[test]
fn the_streets_layer_is_the_noded_network_with_the_blocks_on_either_side() {
    use geo::{Closest, ClosestPoint};
    let d = tmp();
    let out = d.path().join("streets.gpkg");
    let text = format!(
        "input: {{ source: {src}, layer: quarter }}\nsteps:\n  - skeleton: {{}}\n  - prune: {{ junctions: merge }}\n  - extend: {{}}\n  - score: {{}}\n  - select: {{}}\n  - streets: {{ units: {{ source: {src}, layer: quarter_blocks }} }}\noutput: {{ path: {} }}\n",
        out.display(),
        src = root(STREETS),
    );
    let p = pipeline(d.path(), "streets.yaml", &text);
    let o = skeletonise(&["run", p.to_str().unwrap(), "-q"]);
    assert_eq!(code_and_err(&o).0, 0, "{}", code_and_err(&o).1);
    let ds = open(&out);
    let mut layer = ds.layer_by_name("streets").unwrap();
    let fields: Vec<String> = layer.defn().fields().map(|f| f.name()).collect();
    assert!(
        fields.ends_with(
            &[
                "src_fid",
                "piece",
                "start_degree",
                "end_degree",
                "length",
                "left_fid",
                "right_fid"
            ]
            .map(String::from)
        ),
        "{fields:?}"
    );
    let int = |f: &gdal::vector::Feature, name: &str| {
        f.field_as_integer64(f.field_index(name).unwrap()).unwrap()
    };
    let pieces: Vec<Piece> = layer
        .features()
        .map(|f| {
            let g: Geometry<f64> =
                wkt::TryFromWkt::try_from_wkt_str(&f.geometry().unwrap().wkt().unwrap()).unwrap();
            let Geometry::LineString(l) = g else {
                panic!("a line")
            };
            (
                l,
                int(&f, "start_degree").unwrap(),
                int(&f, "end_degree").unwrap(),
                int(&f, "left_fid"),
                int(&f, "right_fid"),
            )
        })
        .collect();
    // The network of the merged skeleton: 12 junctions, 15 ends; every
    // piece runs between two of its nodes.
    let junctions = pieces
        .iter()
        .flat_map(|p| [(p.0 .0[0], p.1), (*p.0 .0.last().unwrap(), p.2)])
        .filter(|(_, deg)| *deg >= 3)
        .map(|(c, _)| (c.x.to_bits(), c.y.to_bits()))
        .collect::<std::collections::HashSet<_>>();
    assert_eq!(junctions.len(), 12);
    let ends = pieces
        .iter()
        .flat_map(|p| [p.1, p.2])
        .filter(|&d| d == 1)
        .count();
    assert_eq!(ends, 15);
    // The nodes of the whole network, made after the last feature: the same
    // 12 junctions and 15 ends, each node's degree the pieces ending there.
    let degrees = crate::common::ints(&ds, "street_nodes", "degree");
    let count = |f: fn(i64) -> bool| degrees.iter().filter(|d| f(d.unwrap())).count();
    assert_eq!(
        (count(|d| d >= 3), count(|d| d == 1), degrees.len()),
        (12, 15, 27)
    );
    let ends_total: i64 = degrees.iter().map(|d| d.unwrap()).sum();
    assert_eq!(ends_total as usize, 2 * pieces.len());
    assert!(crate::common::ints(&ds, "street_nodes", "features")
        .iter()
        .all(|f| *f == Some(1)));
    // Each piece has a block on either side, the two differ, and the one
    // called left lies to the left of the piece where it is nearest to the
    // piece's middle, within the street's width of it.
    let blocks: std::collections::HashMap<i64, Polygon<f64>> = {
        let src = open(Path::new(&root(STREETS)));
        let mut b = src.layer_by_name("quarter_blocks").unwrap();
        b.features()
            .map(|f| {
                let g: Geometry<f64> =
                    wkt::TryFromWkt::try_from_wkt_str(&f.geometry().unwrap().wkt().unwrap())
                        .unwrap();
                let Geometry::Polygon(p) = g else {
                    panic!("a block")
                };
                (f.fid().unwrap() as i64, p)
            })
            .collect()
    };
    // The quarter's box: 500 000–500 600 E, 6 649 960–6 650 370 N.
    let dead_end = |c: Coord<f64>| {
        c.x > 500_016.0 && c.x < 500_584.0 && c.y > 6_649_976.0 && c.y < 6_650_354.0
    };
    for (line, start, end, left, right) in &pieces {
        let (Some(left), Some(right)) = (*left, *right) else {
            panic!("a piece without a block on a side: {line:?} {left:?} {right:?}");
        };
        // The same block on both sides only along a dead end (into a block).
        let into_block = (*start == 1 && dead_end(line.0[0]))
            || (*end == 1 && dead_end(*line.0.last().unwrap()));
        assert_eq!(left == right, into_block, "{line:?}");
        if into_block {
            continue;
        }
        let n = line.0.len();
        let (a, b) = (line.0[n / 2 - usize::from(n % 2 == 0)], line.0[n / 2]);
        let (a, b) = if a == b {
            (line.0[0], line.0[1])
        } else {
            (a, b)
        };
        let mid = (a + b) * 0.5;
        for (fid, sign) in [(left, 1.0), (right, -1.0)] {
            let (Closest::SinglePoint(q) | Closest::Intersection(q)) =
                blocks[&fid].closest_point(&geo::Point(mid))
            else {
                panic!("no closest point")
            };
            let (d, v) = (b - a, q.0 - mid);
            let cross = d.x * v.y - d.y * v.x;
            assert!(
                sign * cross > 0.0,
                "block {fid} is not on that side of {line:?}"
            );
            assert!(
                Euclidean.distance(geo::Point(mid), q) <= 16.0,
                "block {fid} far from {line:?}"
            );
        }
    }
}

#[test]
fn a_side_input_is_checked_by_validate_and_never_written_over() {
    let d = tmp();
    // The blocks copied beside the output, to be written over by mistake.
    let blocks = d.path().join("blocks.gpkg");
    std::fs::copy(root(STREETS), &blocks).unwrap();
    let before = std::fs::read(&blocks).unwrap();
    let text = |layer: &str, out: &Path| {
        format!(
            "input: {{ source: {}, layer: quarter }}\nsteps:\n  - skeleton: {{ methods: [MA] }}\n  - streets: {{ units: {{ source: {}, layer: {layer} }} }}\noutput: {{ path: {}, overwrite: true }}\n",
            root(STREETS),
            blocks.display(),
            out.display()
        )
    };
    // A layer that is not there: `validate` refuses it as `run` does, naming the key.
    let out = d.path().join("out.gpkg");
    let p = pipeline(d.path(), "missing.yaml", &text("nope", &out));
    let (code_v, err_v) = code_and_err(&skeletonise(&["validate", p.to_str().unwrap()]));
    let (code_r, err_r) = code_and_err(&skeletonise(&["run", p.to_str().unwrap(), "-q"]));
    assert_eq!(code_v, code_r, "{err_v}\n{err_r}");
    assert_ne!(code_v, 0);
    for err in [&err_v, &err_r] {
        assert!(
            err.contains("`steps.streets.units`: layer `nope` not found"),
            "{err}"
        );
    }
    assert!(!out.exists());
    // The output onto the side input, even with `overwrite: true`: refused, the file kept.
    let p = pipeline(d.path(), "onto.yaml", &text("quarter_blocks", &blocks));
    let (code, err) = code_and_err(&skeletonise(&["run", p.to_str().unwrap(), "-q"]));
    assert_ne!(code, 0);
    assert!(err.contains("side input"), "{err}");
    assert_eq!(std::fs::read(&blocks).unwrap(), before);
}

#[test]
fn roundabouts_no_wider_than_the_size_given_become_one_node_each_and_blocks_stay_rings() {
    // The real network of `roads` with a roundabout at each of its 12
    // junctions that lie 80 m or more from any other
    // (`scripts/make_roundabouts.py`): a ring road 16 m wide around an
    // island of radius 12 m centred on the junction, the roads meeting it.
    // The islands are holes of the street space, their centres outside it.
    let d = tmp();
    let islands: Vec<Polygon<f64>> = geometries(Path::new(&root(STREETS)), "roundabouts")
        .into_iter()
        .flat_map(|g| match g {
            Geometry::Polygon(p) => vec![p],
            Geometry::MultiPolygon(m) => m.0,
            other => panic!("not a polygon: {other:?}"),
        })
        .collect();
    use geo::Contains;
    let ringed: Vec<Coord<f64>> = points("roundabouts_junctions")
        .into_iter()
        .filter(|&r| !islands.iter().any(|p| p.contains(&r)))
        .collect();
    assert_eq!(ringed.len(), 12);
    let dist = |a: Coord<f64>, b: Coord<f64>| Euclidean.distance(geo::Point(a), geo::Point(b));
    let near = |out: &[Coord<f64>], r: Coord<f64>, within: f64| {
        out.iter().filter(|&&o| dist(o, r) <= within).count()
    };
    let (rings, ring_ends) =
        junctions_and_ends(&run(d.path(), "roundabouts", "{ junctions: merge }"));
    let merged = "{ junctions: merge, roundabouts: 30 }";
    let lines = run(d.path(), "roundabouts", merged);
    let (one, ends) = junctions_and_ends(&lines);
    let mut centres = 0;
    for &r in &ringed {
        // Kept, the ring has a junction where each road meets it (its
        // outer kerb 28 m from the centre); made one node, the roads meet
        // at the island's centre and nowhere else near it. Two of the
        // twelve are on a through road (the reference's junction there is a
        // loop of the line narrower than the road, see above): two roads
        // meet their ring, and the road runs on through the centre.
        assert!(near(&rings, r, 36.0) >= 2, "{r:?}: {rings:?}");
        assert_eq!(near(&one, r, 36.0), near(&one, r, 0.5), "{r:?}: {one:?}");
        centres += near(&one, r, 0.5);
        assert!(Euclidean.distance(&geo::Point(r), &lines) < 0.5, "{r:?}");
    }
    assert_eq!(centres, 10);
    // The network is then the one of the same roads without roundabouts:
    // as many junctions, the same line ends.
    let (plain, plain_ends) = junctions_and_ends(&run(d.path(), "roads", "{ junctions: merge }"));
    assert_eq!(one.len(), plain.len(), "{one:?}\n{plain:?}");
    assert_eq!(ends.len(), plain_ends.len());
    assert_eq!(ends.len(), ring_ends.len());
    // The quarter's blocks (60–100 m across) are wider than 30 m: their
    // rings of streets stay, the lines the same as without the option.
    assert_eq!(
        run(d.path(), "quarter", merged),
        run(d.path(), "quarter", "{ junctions: merge }")
    );
}
