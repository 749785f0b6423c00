//! Step 4 of the module documentation: the cuts at every change of class,
//! the polygon split exactly along them ([`crate::geometry::arrangement`]:
//! its vertices kept bit for bit, a cut's ends inserted into the edges they
//! meet), every face kept or collapsed by the stretches it holds, and the
//! skeleton split at the change points, each piece collapsed or kept as the
//! face it lies in — so no collapsed line ever runs through a kept area.

use super::classify::Samples;
use super::{Area, PartCollapse};
use crate::geometry::arrangement::{self, Face};
use crate::geometry::segment::{lines_meet, properly_cross, segment_parameter};
use crate::geometry::tolerance::SAME_POINT;
use crate::geometry::vector::norm;
use crate::geometry::CoordKey;
use crate::geometry::PreparedPolygon;
use crate::graph::GraphBuilder;
use geo::{Coord, LineString};
use std::collections::HashSet;

/// A change of class on segment `segment` of the samples, at `point`.
struct Change {
    segment: usize,
    point: Coord<f64>,
    /// The cut: from one contact of the inscribed disc at `point` through
    /// it to the other, when both exist.
    cut: Option<LineString<f64>>,
}

/// The collapse of one polygon part from its classified samples.
pub(super) fn split(s: &Samples, p: &PreparedPolygon, min_area: f64) -> PartCollapse {
    let mut changes: Vec<Change> = s.changes().map(|i| change(s, p, i)).collect();
    drop_crossing_cuts(&mut changes);
    let cuts: Vec<LineString<f64>> = changes.iter().filter_map(|c| c.cut.clone()).collect();
    let (cuts, faces) = split_or_whole(p, &cuts);
    let pieces = Pieces::of(s, &changes, p.extent());
    // Each run of pieces lies in one face: placed by its piece farthest
    // from ∂P.
    let face: Vec<Option<usize>> = pieces
        .representatives()
        .into_iter()
        .map(|c| face_of(&faces, c))
        .collect();
    // A face is kept when it holds a wide run, or none at all.
    let mut holds_wide = vec![false; faces.len()];
    let mut holds_any = vec![false; faces.len()];
    for (run, f) in face.iter().enumerate() {
        if let Some(k) = *f {
            holds_any[k] = true;
            holds_wide[k] |= !pieces.run_narrow[run];
        }
    }
    let mut kept: Vec<bool> = (0..faces.len())
        .map(|k| holds_wide[k] || !holds_any[k])
        .collect();
    let was_kept = kept.clone();
    let sides = cut_sides(&faces, cuts.len());
    if min_area > 0.0 {
        collapse_beads(&faces, &sides, &mut kept, min_area);
    }
    let collapsed = |run: usize| face[run].is_some_and(|k| !kept[k]);
    let (collapsed_lines, kept_lines) = pieces.lines(s, collapsed);
    let areas = areas(p, &cuts, &faces, &sides, &kept);
    // The cuts of a collapsed bead are gone with it.
    let gone: Vec<bool> = sides
        .iter()
        .map(|s| s.iter().any(|&k| was_kept[k]) && !s.iter().any(|&k| kept[k]))
        .collect();
    let cuts = cuts
        .into_iter()
        .zip(gone)
        .filter_map(|(c, g)| (!g).then_some(c))
        .collect();
    PartCollapse {
        collapsed: collapsed_lines,
        kept: kept_lines,
        areas,
        cuts,
        ..PartCollapse::default()
    }
}

/// The sampled skeleton cut into pieces wherever it meets a face's
/// boundary — at a change point, where it crosses a cut, at a point where
/// it touches ∂P (rings touching at a vertex) — and the pieces joined into
/// runs: each run lies in one face.
struct Pieces {
    /// From, to, and the run each piece belongs to.
    pieces: Vec<(Coord<f64>, Coord<f64>, usize)>,
    /// Per run: narrow (its samples' class).
    run_narrow: Vec<bool>,
    /// Per run: the piece farthest from ∂P (by the radius at its sample end).
    deepest: Vec<(usize, f64)>,
}

/// A piece of a sample segment before the pieces are joined into runs.
#[derive(Debug, Clone, Copy)]
struct RawPiece {
    from: Coord<f64>,
    to: Coord<f64>,
    /// The class of its samples.
    narrow: bool,
    /// The samples it starts and ends at, when it may be joined there (a
    /// sample away from ∂P).
    ends: [Option<u32>; 2],
    /// The radius at its samples (0 where it starts or ends on a cut).
    depth: f64,
}

/// The cuts' segments, each with the sample segment whose change made it.
struct CutIndex(
    rstar::RTree<rstar::primitives::GeomWithData<rstar::primitives::Line<[f64; 2]>, usize>>,
);

impl CutIndex {
    fn of(changes: &[Change]) -> Self {
        use rstar::primitives::{GeomWithData, Line};
        Self(rstar::RTree::bulk_load(
            changes
                .iter()
                .filter_map(|c| Some((c.segment, c.cut.as_ref()?)))
                .flat_map(|(i, cut)| cut.0.windows(2).map(move |w| (i, w[0], w[1])))
                .map(|(i, a, b)| GeomWithData::new(Line::new([a.x, a.y], [b.x, b.y]), i))
                .collect(),
        ))
    }

    /// Where sample segment `i` (`pa`–`pb`) crosses another change's cut,
    /// by parameter (its own cut meets it at its change point, not across).
    fn crossings(
        &self,
        i: usize,
        pa: Coord<f64>,
        pb: Coord<f64>,
    ) -> impl Iterator<Item = f64> + '_ {
        let env = rstar::AABB::from_corners(
            [pa.x.min(pb.x), pa.y.min(pb.y)],
            [pa.x.max(pb.x), pa.y.max(pb.y)],
        );
        self.0
            .locate_in_envelope_intersecting(&env)
            .filter(move |l| l.data != i)
            .filter_map(move |l| {
                let (c0, c1) = (l.geom().from, l.geom().to);
                let (c0, c1) = (Coord { x: c0[0], y: c0[1] }, Coord { x: c1[0], y: c1[1] });
                properly_cross(pa, pb, c0, c1)
                    .then(|| segment_parameter(pa, pb, c0, c1))
                    .flatten()
            })
    }
}

impl Pieces {
    fn of(s: &Samples, changes: &[Change], extent: f64) -> Self {
        let at_change: std::collections::HashMap<usize, Coord<f64>> =
            changes.iter().map(|c| (c.segment, c.point)).collect();
        let cuts = CutIndex::of(changes);
        let touch = SAME_POINT * extent;
        let mut raw: Vec<RawPiece> = Vec::new();
        for (i, &(a, b, _)) in s.segments.iter().enumerate() {
            let (ia, ib) = (a as usize, b as usize);
            let (pa, pb) = (s.pos[ia], s.pos[ib]);
            let d = pb - pa;
            // Where the segment must be cut, by parameter: its change point
            // and its crossings with other changes' cuts.
            let mut ts: Vec<(f64, bool)> = cuts.crossings(i, pa, pb).map(|t| (t, false)).collect();
            if let Some(&q) = at_change.get(&i) {
                let t = if d.x.abs() >= d.y.abs() {
                    (q.x - pa.x) / d.x
                } else {
                    (q.y - pa.y) / d.y
                };
                ts.push((t, true));
            }
            ts.sort_by(|x, y| x.0.total_cmp(&y.0));
            let joinable = |k: usize| (s.r[k] > touch).then_some(k as u32);
            let mut piece = RawPiece {
                from: pa,
                to: pb,
                narrow: s.narrow[ia],
                ends: [joinable(ia), None],
                depth: s.r[ia],
            };
            for &(t, is_change) in &ts {
                let q = pa + d * t;
                if q != piece.from {
                    raw.push(RawPiece { to: q, ..piece });
                    piece = RawPiece {
                        from: q,
                        ends: [None, None],
                        depth: 0.0,
                        ..piece
                    };
                }
                if is_change {
                    piece.narrow = s.narrow[ib];
                }
            }
            piece.ends[1] = joinable(ib);
            piece.depth = piece.depth.max(s.r[ib]);
            raw.push(piece);
        }
        Self::runs(&raw)
    }

    /// The pieces joined into runs through the samples they share.
    fn runs(raw: &[RawPiece]) -> Self {
        let mut uf = crate::graph::UnionFind::new(raw.len());
        let mut first_at: std::collections::HashMap<u32, usize> = Default::default();
        for (k, r) in raw.iter().enumerate() {
            for v in r.ends.iter().flatten() {
                match first_at.get(v) {
                    Some(&j) => uf.union(j, k),
                    None => {
                        first_at.insert(*v, k);
                    }
                }
            }
        }
        let mut run_of_root: std::collections::HashMap<usize, usize> = Default::default();
        let mut run_narrow = Vec::new();
        let mut deepest: Vec<(usize, f64)> = Vec::new();
        let mut pieces = Vec::with_capacity(raw.len());
        for (k, r) in raw.iter().enumerate() {
            let root = uf.find(k);
            let run = *run_of_root.entry(root).or_insert_with(|| {
                run_narrow.push(r.narrow);
                deepest.push((k, f64::NEG_INFINITY));
                run_narrow.len() - 1
            });
            if r.depth > deepest[run].1 {
                deepest[run] = (k, r.depth);
            }
            pieces.push((r.from, r.to, run));
        }
        Self {
            pieces,
            run_narrow,
            deepest,
        }
    }

    /// A point of every run: the middle of its deepest piece.
    fn representatives(&self) -> Vec<Coord<f64>> {
        self.deepest
            .iter()
            .map(|&(k, _)| (self.pieces[k].0 + self.pieces[k].1) * 0.5)
            .collect()
    }

    /// The pieces as lines, collapsed or kept by their run, without the
    /// vertices the sampling inserted.
    fn lines(
        &self,
        s: &Samples,
        collapsed: impl Fn(usize) -> bool,
    ) -> (Vec<LineString<f64>>, Vec<LineString<f64>>) {
        let mut parts = [GraphBuilder::new(), GraphBuilder::new()];
        for &(a, b, run) in &self.pieces {
            parts[usize::from(!collapsed(run))].segment(a, b);
        }
        let inserted: HashSet<CoordKey> = (0..s.pos.len())
            .filter(|&i| s.inserted[i])
            .map(|i| CoordKey::from(s.pos[i]))
            .collect();
        let [c, k] = parts.map(|b| {
            b.finish_raw()
                .to_multilinestring()
                .0
                .into_iter()
                .map(|l| {
                    let n = l.0.len();
                    LineString(
                        l.0.iter()
                            .enumerate()
                            .filter(|&(j, p)| {
                                j == 0 || j == n - 1 || !inserted.contains(&CoordKey::from(p))
                            })
                            .map(|(_, p)| *p)
                            .collect(),
                    )
                })
                .collect()
        });
        (c, k)
    }
}

/// The faces of `p` split by `cuts`, leaving out any cut that does not
/// end on the boundary (not expected: contacts are boundary points).
/// Returns the cuts used, which the faces' chord indices refer to.
fn split_or_whole(
    p: &PreparedPolygon,
    cuts: &[LineString<f64>],
) -> (Vec<LineString<f64>>, Vec<Face>) {
    let mut cuts = cuts.to_vec();
    loop {
        match arrangement::split(p, &cuts) {
            Ok(faces) => return (cuts, faces),
            Err(arrangement::SplitError::Detached(k)) => {
                cuts.remove(k);
            }
        }
    }
}

/// The faces on either side of every cut (indices into `faces`).
fn cut_sides(faces: &[Face], n_cuts: usize) -> Vec<Vec<usize>> {
    let mut sides: Vec<Vec<usize>> = vec![Vec::new(); n_cuts];
    for (k, f) in faces.iter().enumerate() {
        for &c in &f.chords {
            sides[c].push(k);
        }
    }
    sides
}

/// `collapse.min_area`: kept areas (kept faces joined across the cuts
/// between them) smaller than `min_area` and bounded by at least one cut
/// become collapsed. Beyond each of an area's cuts lies a collapsed face (a
/// kept one would belong to the area), so every such area is a bead with
/// collapsed lines on all its cuts.
fn collapse_beads(faces: &[Face], sides: &[Vec<usize>], kept: &mut [bool], min_area: f64) {
    use geo::Area as _;
    let mut group: Vec<usize> = (0..faces.len()).collect();
    fn root(g: &mut [usize], mut a: usize) -> usize {
        while g[a] != a {
            g[a] = g[g[a]];
            a = g[a];
        }
        a
    }
    for s in sides {
        for w in s.windows(2) {
            if kept[w[0]] && kept[w[1]] {
                let (a, b) = (root(&mut group, w[0]), root(&mut group, w[1]));
                group[a] = b;
            }
        }
    }
    let mut areas: std::collections::BTreeMap<usize, (f64, bool, Vec<usize>)> = Default::default();
    for k in (0..faces.len()).filter(|&k| kept[k]) {
        let g = root(&mut group, k);
        let cut = faces[k]
            .chords
            .iter()
            .any(|&c| sides[c].iter().any(|&o| !kept[o]));
        let e = areas.entry(g).or_default();
        e.0 += faces[k].polygon.unsigned_area();
        e.1 |= cut;
        e.2.push(k);
    }
    for (area, cut, members) in areas.into_values() {
        if cut && area < min_area {
            for k in members {
                kept[k] = false;
            }
        }
    }
}

/// The kept areas: the faces of `p` split only by the cuts between a kept
/// and a collapsed face (kept faces that share a cut are one area), each
/// with the number of cuts on its boundary.
fn areas(
    p: &PreparedPolygon,
    cuts: &[LineString<f64>],
    faces: &[Face],
    sides: &[Vec<usize>],
    kept: &[bool],
) -> Vec<Area> {
    let between: Vec<LineString<f64>> = cuts
        .iter()
        .zip(sides)
        .filter(|(_, s)| s.iter().any(|&k| kept[k]) && s.iter().any(|&k| !kept[k]))
        .map(|(c, _)| c.clone())
        .collect();
    let (_, merged) = split_or_whole(p, &between);
    merged
        .into_iter()
        .filter(|m| {
            // Of the first split's faces, those inside this one decide.
            faces
                .iter()
                .zip(kept)
                .find(|(f, _)| interior_point(f).is_some_and(|c| in_face(m, c)))
                .is_none_or(|(_, &k)| k)
        })
        .map(|m| Area {
            cuts: m.chords.len(),
            polygon: m.polygon,
        })
        .collect()
}

/// A point strictly inside a face: the middle of the shortest of the
/// segments from a vertex of its shell's first edge straight across into
/// the face, found by casting along the inward normal of that edge.
fn interior_point(f: &Face) -> Option<Coord<f64>> {
    let ring = f.polygon.exterior();
    for w in ring.0.windows(2) {
        let d = w[1] - w[0];
        let len = norm(d);
        if len == 0.0 {
            continue;
        }
        // The shell is counter-clockwise: the face is on the left.
        let n = Coord {
            x: -d.y / len,
            y: d.x / len,
        };
        let m = (w[0] + w[1]) * 0.5;
        // The nearest crossing of the ray from m along n with any ring.
        let mut t_min = f64::INFINITY;
        for r in std::iter::once(ring).chain(f.polygon.interiors()) {
            for e in r.0.windows(2) {
                if e[0] == w[0] && e[1] == w[1] {
                    continue;
                }
                if let Some(t) = ray_hit(m, n, e[0], e[1]) {
                    t_min = t_min.min(t);
                }
            }
        }
        if t_min.is_finite() && t_min > 0.0 {
            return Some(m + n * (0.5 * t_min));
        }
    }
    None
}

/// Where the ray `o + t n` (t > 0) meets segment `a`–`b`.
fn ray_hit(o: Coord<f64>, n: Coord<f64>, a: Coord<f64>, b: Coord<f64>) -> Option<f64> {
    let (t, u) = lines_meet(o, n, a, b)?;
    (t > 0.0 && (0.0..=1.0).contains(&u)).then_some(t)
}

/// The face that holds `c`.
fn face_of(faces: &[Face], c: Coord<f64>) -> Option<usize> {
    faces.iter().position(|f| in_face(f, c))
}

/// Whether `c` lies in face `f` (inside its shell, outside its holes).
fn in_face(f: &Face, c: Coord<f64>) -> bool {
    let inside = |r: &LineString<f64>| {
        let mut inside = false;
        for w in r.0.windows(2) {
            let (a, b) = (w[0], w[1]);
            if (a.y > c.y) != (b.y > c.y) && c.x < a.x + (c.y - a.y) / (b.y - a.y) * (b.x - a.x) {
                inside = !inside;
            }
        }
        inside
    };
    inside(f.polygon.exterior()) && !f.polygon.interiors().iter().any(inside)
}

/// Cuts that cross an earlier one are left out (the inscribed discs'
/// radii do not cross; an approximate contact could make two do so, and a
/// crossing would not split the polygon into faces).
fn drop_crossing_cuts(changes: &mut [Change]) {
    let mut kept: Vec<LineString<f64>> = Vec::new();
    for c in changes.iter_mut() {
        let Some(cut) = &c.cut else { continue };
        let crosses = kept.iter().any(|k| {
            cut.0.windows(2).any(|a| {
                k.0.windows(2)
                    .any(|b| properly_cross(a[0], a[1], b[0], b[1]))
            })
        });
        if crosses {
            c.cut = None;
        } else {
            kept.push(cut.clone());
        }
    }
}

/// The change on segment `i`: where the width crosses the collapse width
/// (the segment's middle when it does not), and the cut through it.
fn change(s: &Samples, p: &PreparedPolygon, i: usize) -> Change {
    let (a, b, _) = s.segments[i];
    let (a, b) = (a as usize, b as usize);
    let (da, db) = (2.0 * s.r[a] - s.width, 2.0 * s.r[b] - s.width);
    let t = if (da < 0.0) != (db < 0.0) && da != db {
        da / (da - db)
    } else {
        0.5
    };
    // Never on a sample: a cut through a junction would split its legs.
    let t = t.clamp(0.1, 0.9);
    let point = super::lerp(s.pos[a], s.pos[b], t);
    let d = s.pos[b] - s.pos[a];
    let normal = Coord { x: -d.y, y: d.x };
    let boundary = p.boundary();
    let r = boundary.distance(point);
    let cut = (r > 0.0)
        .then(|| {
            let snap = |c: Coord<f64>| snap_to_vertex(p, c);
            let (left, _) = boundary.nearest_in_half_plane(point, normal)?;
            let (right, _) = boundary.nearest_in_half_plane(point, -normal)?;
            let (left, right) = (snap(left), snap(right));
            (left != point && right != point && left != right)
                .then(|| LineString(vec![left, point, right]))
        })
        .flatten();
    Change {
        segment: i,
        point,
        cut,
    }
}

/// A contact on ∂P, moved onto the vertex of its edge when within
/// `1e-9 × extent` of it: a disc touching a reflex vertex touches the
/// vertex, and two cuts to one vertex must end on the same point (a contact
/// a hair beside it can make them cross).
fn snap_to_vertex(p: &PreparedPolygon, c: Coord<f64>) -> Coord<f64> {
    let Some((_, i, _)) = p.boundary().nearest(c) else {
        return c;
    };
    let s = &p.boundary().segments()[i];
    let eps = SAME_POINT * p.extent();
    if norm(c - s.a) <= eps {
        s.a
    } else if norm(c - s.b) <= eps {
        s.b
    } else {
        c
    }
}
