//! Junctions of a network of corridors merged into one node each
//! (`prune: { junctions: merge }`): where streets or roads cross, the medial
//! axis of the street space has two three-way nodes joined by a short stub
//! for every four-way crossing, and a small triangle or ladder for a skewed
//! or wide one. A cartographer's street network has one node per junction.
//!
//! The rule: two junctions (nodes of degree ≥ 3) joined by a branch whose
//! inscribed discs overlap — the branch is no longer than `r_a + r_b`, and
//! so are the centres apart — are one junction; chains of such pairs are one
//! cluster. Each cluster of two or more junctions becomes one node at the
//! centre of its largest inscribed disc (the widest point of the junction
//! area, inside the polygon), the branches between its members go, and every
//! other branch that meets it is cut where it leaves that disc and runs
//! straight to the centre (or straight from the member it started at, whose
//! disc overlaps the centre's). A straight segment from the centre to the
//! disc's rim lies inside the disc, and from the centre to a member inside
//! the two overlapping discs, so the lines stay inside the polygon. A leg
//! wholly inside the merged disc (a corner of the junction area) goes with
//! the stubs. A cluster with a member whose disc does not overlap the
//! centre's is left as it is, and so is one whose members' own streets meet
//! at points farther apart than their radii (a staggered crossing: side
//! streets leaving a through street a street's width apart are two
//! junctions, not the halves of one crossing) or whose merge would run a
//! line back through the disc's centre. Branches that are not between two
//! members of a cluster keep every vertex beyond the disc.

use super::{Branch, GraphBuilder, NodeId, SkeletonGraph, UnionFind};
use crate::geometry::vector::norm;
use crate::geometry::{CoordKey, PreparedPolygon};
use geo::Coord;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// What `prune` does with junctions close to each other.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Junctions {
    /// Every junction of the skeleton stays (rivers, lakes, islands).
    #[default]
    Keep,
    /// Junctions whose inscribed discs overlap become one node at the
    /// centre of the largest disc, the lines straightened into it, and a
    /// cut that is not quite straight is a cut (street and road networks).
    Merge,
}

/// One cluster of merged junctions: the centre and radius of its largest
/// inscribed disc, and the node where its lines meet (inside that disc).
#[derive(Debug, Clone, Copy)]
struct Hub {
    centre: Coord<f64>,
    radius: f64,
    node: Coord<f64>,
}

/// `g` with the junctions whose discs overlap merged (see the module
/// documentation); `g` itself when no two junctions are that close.
pub fn merge(g: &SkeletonGraph, polygon: &PreparedPolygon) -> SkeletonGraph {
    let degrees = g.degrees();
    let junction = |n: NodeId| degrees[n.index()] >= 3;
    let branches = g.branches();
    let (mut hubs, mut inner) = hubs(g, &branches, &junction);
    // Every other junction a hub of its own: its lines too meet at one point.
    for (i, h) in hubs.iter_mut().enumerate() {
        if h.is_none() && degrees[i] >= 3 {
            *h = Some(own_hub(g, i));
        }
    }
    if hubs.iter().all(Option::is_none) {
        return g.clone();
    }
    let mut lines = straightened(&mut hubs, &branches, &inner, polygon);
    let undo = doubled_back(&hubs, &branches, &inner, &lines);
    if !undo.is_empty() {
        let undone: Vec<bool> = hubs
            .iter()
            .map(|h| h.is_some_and(|h| undo.contains(&CoordKey::from(h.centre))))
            .collect();
        for (i, h) in hubs.iter_mut().enumerate().filter(|(i, _)| undone[*i]) {
            *h = Some(own_hub(g, i));
        }
        for (k, br) in branches.iter().enumerate() {
            inner[k] &= !undone[br.start.index()];
        }
        lines = straightened(&mut hubs, &branches, &inner, polygon);
    }
    let mut b = GraphBuilder::new();
    for (coords, _) in lines.iter().flatten() {
        // A loop from a hub back to it: two edges through its middle.
        b.path(coords);
    }
    let merged = b.finish(polygon.boundary());
    super::planar::node_crossings(merged, polygon.boundary()).0
}

/// Node `i` of `g` a hub of its own.
fn own_hub(g: &SkeletonGraph, i: usize) -> Hub {
    let n = &g.nodes()[i];
    Hub {
        centre: n.pos,
        radius: n.radius,
        node: n.pos,
    }
}

/// Every branch that is not between two members of a hub, straightened into
/// the hubs at its ends (after placing each hub's node where its lines
/// meet), with whether it reaches the hub at its start and at its end
/// through the disc's centre; `None` for a leg wholly inside a merged disc.
type Straightened = Option<(Vec<Coord<f64>>, [bool; 2])>;

fn straightened(
    hubs: &mut [Option<Hub>],
    branches: &[Branch],
    inner: &[bool],
    polygon: &PreparedPolygon,
) -> Vec<Straightened> {
    // A junction a hub of its own (no branch between it and another member).
    let mut single: Vec<bool> = hubs.iter().map(Option::is_some).collect();
    for (br, _) in branches.iter().zip(inner).filter(|(_, &x)| x) {
        single[br.start.index()] = false;
        single[br.end.index()] = false;
    }
    meeting_points(hubs, branches, inner, &single, polygon);
    let boundary = polygon.boundary();
    branches
        .iter()
        .zip(inner)
        .map(|(br, &inside)| {
            if inside {
                return None;
            }
            let mut coords = br.coords.clone();
            let mut via = [false; 2];
            if let Some(h) = hubs[br.start.index()] {
                (coords, via[0]) = straighten(&coords, h, boundary);
            }
            if let Some(h) = hubs[br.end.index()] {
                coords.reverse();
                (coords, via[1]) = straighten(&coords, h, boundary);
                coords.reverse();
            }
            // Fewer than two points: a leg wholly inside the merged disc.
            (coords.len() >= 2).then_some((coords, via))
        })
        .collect()
}

/// The hubs (by their centre) whose merge would double a line back: a
/// branch from a member outside the centre's disc reaches the node through
/// the centre (its straight way in is not clear of ∂P) while the node lies
/// off the centre (node → centre → member turns back on itself) or the
/// member has two such branches (they would share the segment to it). Such
/// junctions are two junctions, as a staggered crossing's are.
fn doubled_back(
    hubs: &[Option<Hub>],
    branches: &[Branch],
    inner: &[bool],
    lines: &[Straightened],
) -> Vec<CoordKey> {
    let mut outer = vec![0usize; hubs.len()];
    for (br, _) in branches.iter().zip(inner).filter(|(_, &x)| !x) {
        outer[br.start.index()] += 1;
        outer[br.end.index()] += 1;
    }
    let mut undo = Vec::new();
    for (br, line) in branches.iter().zip(lines) {
        let Some((_, via)) = line else { continue };
        for (n, through) in [(br.start, via[0]), (br.end, via[1])] {
            let Some(h) = hubs[n.index()].filter(|_| through) else {
                continue;
            };
            if h.node != h.centre || outer[n.index()] >= 2 {
                undo.push(CoordKey::from(h.centre));
            }
        }
    }
    undo.sort_unstable();
    undo.dedup();
    undo
}

/// The hub of every node (the merged cluster it belongs to, when the
/// cluster has two junctions or more and every member's disc overlaps the
/// centre's), and which branches lie between two members of one hub.
fn hubs(
    g: &SkeletonGraph,
    branches: &[Branch],
    junction: &dyn Fn(NodeId) -> bool,
) -> (Vec<Option<Hub>>, Vec<bool>) {
    let node = |n: NodeId| g.node(n);
    let close = |br: &Branch| {
        let (a, b) = (node(br.start), node(br.end));
        let reach = a.radius + b.radius;
        br.start != br.end
            && junction(br.start)
            && junction(br.end)
            && br.length() <= reach
            && norm(a.pos - b.pos) <= reach
    };
    let mut uf = UnionFind::new(g.nodes().len());
    for br in branches.iter().filter(|br| close(br)) {
        uf.union(br.start.index(), br.end.index());
    }
    let n = g.nodes().len();
    let root: Vec<usize> = (0..n).map(|i| uf.find(i)).collect();
    let apart = staggered(g, branches, &close, &root);
    // The member with the largest disc of each cluster (the smallest index
    // among equals), and the cluster's size.
    let mut best: Vec<Option<usize>> = vec![None; n];
    let mut size = vec![0usize; n];
    for (i, &r) in root.iter().enumerate() {
        size[r] += 1;
        let wider = best[r].is_none_or(|b| g.nodes()[i].radius > g.nodes()[b].radius);
        if wider {
            best[r] = Some(i);
        }
    }
    let mut hub: Vec<Option<Hub>> = vec![None; n];
    let mut ok: Vec<bool> = apart.iter().map(|&a| !a).collect();
    for (i, &r) in root.iter().enumerate() {
        let Some(c) = best[r].filter(|_| size[r] >= 2) else {
            continue;
        };
        let (ci, ni) = (&g.nodes()[c], &g.nodes()[i]);
        if norm(ni.pos - ci.pos) > ci.radius + ni.radius {
            ok[r] = false;
        }
        hub[i] = Some(Hub {
            centre: ci.pos,
            radius: ci.radius,
            node: ci.pos,
        });
    }
    for (h, &r) in hub.iter_mut().zip(&root) {
        if !ok[r] {
            *h = None;
        }
    }
    let inner = branches
        .iter()
        .map(|br| {
            let same = root[br.start.index()] == root[br.end.index()];
            let merged = hub[br.start.index()].is_some();
            let inside = |c: &Coord<f64>, h: Hub| norm(*c - h.centre) <= h.radius;
            // Between two members: a stub (or a short side of a triangle),
            // or any branch that stays inside the merged disc.
            merged
                && same
                && (close(br)
                    || hub[br.start.index()]
                        .is_some_and(|h| br.coords.iter().all(|c| inside(c, h))))
        })
        .collect();
    (hub, inner)
}

/// Where each hub's lines meet: the point nearest (least squares) to the
/// lines that continue its incoming branches beyond its disc — the crossing
/// of the streets' centrelines — kept inside the disc; the disc's centre
/// where the branches are (nearly) parallel.
fn meeting_points(
    hubs: &mut [Option<Hub>],
    branches: &[Branch],
    inner: &[bool],
    single: &[bool],
    polygon: &PreparedPolygon,
) {
    use std::collections::HashMap;
    // Per hub (by its centre): Σ (I − d dᵀ) and Σ (I − d dᵀ) q.
    let mut sums: HashMap<CoordKey, [f64; 5]> = HashMap::new();
    let mut meeting: HashMap<CoordKey, Coord<f64>> = HashMap::new();
    let key = |h: &Hub| CoordKey::from(h.centre);
    for (br, _) in branches.iter().zip(inner).filter(|(_, &i)| !i) {
        for (n, coords) in [
            (br.start, br.coords.clone()),
            (br.end, reversed(&br.coords)),
        ] {
            let Some(h) = hubs[n.index()] else { continue };
            let Some((q, d)) = direction_beyond(&coords, h) else {
                continue;
            };
            add_line(sums.entry(key(&h)).or_insert([0.0; 5]), q, d);
        }
    }
    for h in hubs.iter_mut().flatten() {
        let Some(x) = sums.get(&key(h)).and_then(|&sum| meet(sum)) else {
            continue;
        };
        let off = x - h.centre;
        let l = norm(off);
        h.node = if l <= h.radius {
            x
        } else {
            h.centre + off * (h.radius / l)
        };
        meeting.insert(key(h), x);
    }
    relocate_singles(hubs, branches, single, &meeting, polygon);
}

/// Adds the line through `q` with unit direction `d` to the least-squares
/// sums Σ (I − d dᵀ) and Σ (I − d dᵀ) q.
fn add_line(sums: &mut [f64; 5], q: Coord<f64>, d: Coord<f64>) {
    let (a, b, c) = (1.0 - d.x * d.x, -d.x * d.y, 1.0 - d.y * d.y);
    sums[0] += a;
    sums[1] += b;
    sums[2] += c;
    sums[3] += a * q.x + b * q.y;
    sums[4] += b * q.x + c * q.y;
}

/// The point nearest (least squares) to the lines summed in `sums`; `None`
/// when they are nearly parallel (a straight street through a widening: no
/// crossing to speak of).
fn meet([a, b, c, u, v]: [f64; 5]) -> Option<Coord<f64>> {
    let det = a * c - b * b;
    if det.is_nan() || det <= 0.05 * (a + c) * (a + c) / 4.0 {
        return None;
    }
    Some(Coord {
        x: (c * u - b * v) / det,
        y: (a * v - b * u) / det,
    })
}

/// Per cluster (by its root in `root`): whether its members' own streets
/// meet at different points — each member's outer branches (those not
/// `close` to another member) continued as lines beyond its disc, met by
/// least squares; two members whose points lie farther apart than the
/// larger of their radii are two junctions one street apart (a staggered
/// crossing: two T-junctions whose side streets leave the through street
/// a street's width apart), not the two halves of one crossing, whose
/// streets all meet at one point. Members whose outer lines are parallel or
/// fewer than two give no point.
fn staggered(
    g: &SkeletonGraph,
    branches: &[Branch],
    close: &dyn Fn(&Branch) -> bool,
    root: &[usize],
) -> Vec<bool> {
    let n = g.nodes().len();
    let mut size = vec![0usize; n];
    for &r in root {
        size[r] += 1;
    }
    // Only members of clusters of two or more have a partner to differ from.
    let member = |m: NodeId| size[root[m.index()]] >= 2;
    let mut sums = vec![[0.0; 5]; n];
    for br in branches.iter().filter(|br| !close(br)) {
        if member(br.start) {
            let i = br.start.index();
            if let Some((q, d)) = direction_beyond(&br.coords, own_hub(g, i)) {
                add_line(&mut sums[i], q, d);
            }
        }
        if member(br.end) {
            let i = br.end.index();
            if let Some((q, d)) = direction_beyond(&reversed(&br.coords), own_hub(g, i)) {
                add_line(&mut sums[i], q, d);
            }
        }
    }
    let mut points: Vec<Vec<(Coord<f64>, f64)>> = vec![Vec::new(); n];
    for (i, &r) in root.iter().enumerate() {
        if let Some(x) = meet(sums[i]) {
            points[r].push((x, g.nodes()[i].radius));
        }
    }
    points
        .iter()
        .map(|p| {
            p.iter()
                .enumerate()
                .any(|(k, &(x, rx))| p[k + 1..].iter().any(|&(y, ry)| norm(x - y) > rx.max(ry)))
        })
        .collect()
}

/// A single junction whose lines meet beyond its disc (a Y whose arms part
/// at an acute angle: the medial axis forks where the corridors separate,
/// past where their centrelines meet, `meeting`) moves there when every
/// line reaches it straight inside the polygon.
fn relocate_singles(
    hubs: &mut [Option<Hub>],
    branches: &[Branch],
    single: &[bool],
    meeting: &std::collections::HashMap<CoordKey, Coord<f64>>,
    polygon: &PreparedPolygon,
) {
    let key = |h: &Hub| CoordKey::from(h.centre);
    // The branches at each node: (branch, whether it starts there).
    let mut at: Vec<Vec<(usize, bool)>> = vec![Vec::new(); hubs.len()];
    for (k, br) in branches.iter().enumerate() {
        at[br.start.index()].push((k, true));
        at[br.end.index()].push((k, false));
    }
    for (i, slot) in hubs.iter_mut().enumerate() {
        let Some(h) = slot.as_mut().filter(|_| single[i]) else {
            continue;
        };
        let Some(&x) = meeting.get(&key(h)) else {
            continue;
        };
        let reach = norm(x - h.centre);
        if reach <= h.radius {
            continue;
        }
        let moved = Hub {
            centre: x,
            radius: reach + h.radius,
            node: x,
        };
        let boundary = polygon.boundary();
        let inside = boundary.contains(x)
            && at[i].iter().all(|&(k, starts)| {
                let coords = match starts {
                    true => branches[k].coords.clone(),
                    false => reversed(&branches[k].coords),
                };
                let (cut, _) = into_hub(&coords, moved);
                cut.len() >= 2 && !boundary.crosses(cut[0], cut[1])
            });
        if inside {
            *h = moved;
        }
    }
}

/// `coords` reversed.
fn reversed(coords: &[Coord<f64>]) -> Vec<Coord<f64>> {
    coords.iter().rev().copied().collect()
}

/// A branch leaving hub `h` (`coords` from the hub) as a line beyond the
/// disc: its point one disc radius past the rim, and its direction from
/// there to its point three radii past the rim (or its end) — clear of the
/// bend the junction's corners give the medial axis. A branch ending within
/// a radius past the rim (a short street between two junctions) is the line
/// through its two ends: without it a T-junction's through street alone
/// leaves the meeting point anywhere along it.
fn direction_beyond(coords: &[Coord<f64>], h: Hub) -> Option<(Coord<f64>, Coord<f64>)> {
    let (_, rest) = beyond(coords, h)?;
    let mut near = along(&rest, h.radius);
    let far = along(&rest, 3.0 * h.radius);
    if far == near {
        near = coords[0];
    }
    let d = far - near;
    let l = norm(d);
    (l > 0.0).then(|| (near, d / l))
}

/// The point `s` along polyline `c` from its start (its end when shorter).
fn along(c: &[Coord<f64>], s: f64) -> Coord<f64> {
    let mut left = s;
    for w in c.windows(2) {
        let l = norm(w[1] - w[0]);
        if l >= left && l > 0.0 {
            return w[0] + (w[1] - w[0]) * (left / l);
        }
        left -= l;
    }
    c[c.len() - 1]
}

/// The part of `coords` (starting at a member of hub `h`) beyond the hub's
/// disc, from where it first leaves it (a point on the rim), and whether it
/// started outside the disc already (a member farther than the disc's
/// radius, whose own disc overlaps it); `None` when it never leaves it.
fn beyond(coords: &[Coord<f64>], h: Hub) -> Option<(bool, Vec<Coord<f64>>)> {
    let outside = |c: Coord<f64>| norm(c - h.centre) > h.radius;
    let first_out = coords.iter().position(|&c| outside(c))?;
    if first_out == 0 {
        return Some((true, coords.to_vec()));
    }
    let (a, b) = (coords[first_out - 1], coords[first_out]);
    let mut rest = vec![rim(a, b, h)];
    rest.extend_from_slice(&coords[first_out..]);
    rest.dedup();
    Some((false, rest))
}

/// `coords` (starting at a member of hub `h`) from the hub's node: cut
/// where it first leaves the hub's disc and joined to the node by a
/// straight segment (inside the disc, which is convex and inside the
/// polygon). A polyline that never leaves the disc is the node alone; one
/// that starts outside the disc is joined to its start through the disc's
/// centre (the segment from the centre to the member lies in their two
/// overlapping discs).
fn into_hub(coords: &[Coord<f64>], h: Hub) -> (Vec<Coord<f64>>, bool) {
    let mut out = vec![h.node];
    let mut through = false;
    if let Some((outside, rest)) = beyond(coords, h) {
        if outside {
            out.push(h.centre);
            through = true;
        }
        out.extend(rest);
    }
    out.dedup();
    (out, through)
}

/// `coords` (from a member of hub `h`) into the hub's node: cut at twice
/// the disc's radius where the straight segment from the node stays clear
/// of the boundary (half the disc's radius or more all along it: past the
/// bend the junction's corners give the medial axis), else at the disc
/// ([`into_hub`]); a branch wholly inside the disc is the node alone.
fn straighten(
    coords: &[Coord<f64>],
    h: Hub,
    boundary: &crate::geometry::Boundary,
) -> (Vec<Coord<f64>>, bool) {
    let near = into_hub(coords, h);
    if near.0.len() < 2 {
        return near;
    }
    let (far, _) = into_hub(
        coords,
        Hub {
            radius: 2.0 * h.radius,
            ..h
        },
    );
    let clear = |a: Coord<f64>, b: Coord<f64>| {
        !boundary.crosses(a, b)
            && (0..=8)
                .all(|k| boundary.distance(a + (b - a) * (f64::from(k) / 8.0)) >= 0.5 * h.radius)
    };
    if far.len() >= 2 && clear(far[0], far[1]) {
        (far, false)
    } else {
        near
    }
}

/// Where segment `a`–`b` (`a` inside disc `h`, `b` outside) crosses its rim.
fn rim(a: Coord<f64>, b: Coord<f64>, h: Hub) -> Coord<f64> {
    let d = b - a;
    let f = a - h.centre;
    let (qa, qb, qc) = (
        d.x * d.x + d.y * d.y,
        2.0 * (f.x * d.x + f.y * d.y),
        f.x * f.x + f.y * f.y - h.radius * h.radius,
    );
    let disc = (qb * qb - 4.0 * qa * qc).max(0.0);
    let t = if qa > 0.0 {
        ((-qb + disc.sqrt()) / (2.0 * qa)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    a + d * t
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::GraphBuilder;
    use geo::polygon;

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    /// `p`'s medial axis, pruned and extended with the default options.
    fn pruned_axis(p: &PreparedPolygon) -> SkeletonGraph {
        let raw = crate::methods::build(
            crate::methods::MethodId::MA,
            &crate::methods::SkeletonParams::default(),
        )
        .skeletonise(p, &crate::methods::MethodContext::default())
        .unwrap();
        crate::graph::extend::prune_and_extend(
            &raw,
            p,
            Some(&crate::graph::prune::PruneParams::default()),
            Some(&crate::graph::extend::ExtendParams::default()),
        )
    }

    #[test]
    fn a_crossing_seen_as_two_three_way_nodes_becomes_one_four_way_node() {
        // A plus-shaped street space, arms 10 wide: its medial axis as two
        // three-way nodes 1 apart (as MA gives a crossing that is not
        // perfectly symmetric), joined by a stub.
        let p = PreparedPolygon::new(&polygon![
            (x: -5., y: -50.), (x: 5., y: -50.), (x: 5., y: -5.), (x: 50., y: -5.),
            (x: 50., y: 5.), (x: 5., y: 5.), (x: 5., y: 50.), (x: -5., y: 50.),
            (x: -5., y: 5.), (x: -50., y: 5.), (x: -50., y: -5.), (x: -5., y: -5.)
        ])
        .unwrap();
        let mut b = GraphBuilder::new();
        b.segment(c(-0.5, 0.), c(0.5, 0.));
        b.polyline(&[c(-0.5, 0.), c(-50., 0.)]);
        b.polyline(&[c(-0.5, 0.), c(-0.2, 50.)]);
        b.polyline(&[c(0.5, 0.), c(50., 0.)]);
        b.polyline(&[c(0.5, 0.), c(0.2, -50.)]);
        let g = b.finish(p.boundary());
        assert_eq!(g.degrees().iter().filter(|&&d| d >= 3).count(), 2);
        let m = merge(&g, &p);
        let degrees = m.degrees();
        assert_eq!(degrees.iter().filter(|&&d| d >= 3).count(), 1, "{m:?}");
        assert_eq!(degrees.iter().filter(|&&d| d == 4).count(), 1);
        assert_eq!(degrees.iter().filter(|&&d| d == 1).count(), 4);
        // The arms keep their far ends; the total length lost is the stub.
        assert!((g.total_length() - m.total_length()).abs() < 2.0);
        m.check_invariants().unwrap();
    }

    #[test]
    fn junctions_farther_apart_than_their_discs_stay() {
        // Two T-junctions 30 apart along a street 10 wide: two junctions.
        let p = PreparedPolygon::new(&polygon![
            (x: -50., y: -5.), (x: 50., y: -5.), (x: 50., y: 5.), (x: 20., y: 5.),
            (x: 20., y: 50.), (x: 10., y: 50.), (x: 10., y: 5.), (x: -10., y: 5.),
            (x: -10., y: 50.), (x: -20., y: 50.), (x: -20., y: 5.), (x: -50., y: 5.)
        ])
        .unwrap();
        let mut b = GraphBuilder::new();
        b.polyline(&[c(-50., 0.), c(-15., 0.)]);
        b.polyline(&[c(-15., 0.), c(15., 0.)]);
        b.polyline(&[c(15., 0.), c(50., 0.)]);
        b.polyline(&[c(-15., 0.), c(-15., 50.)]);
        b.polyline(&[c(15., 0.), c(15., 50.)]);
        let g = b.finish(p.boundary());
        let m = merge(&g, &p);
        let d = m.degrees();
        let mut junctions: Vec<(f64, f64)> = (0..d.len())
            .filter(|&i| d[i] == 3)
            .map(|i| (m.nodes()[i].pos.x, m.nodes()[i].pos.y))
            .collect();
        junctions.sort_by(|a, b| a.0.total_cmp(&b.0));
        assert_eq!(junctions, vec![(-15.0, 0.0), (15.0, 0.0)]);
        assert!((g.total_length() - m.total_length()).abs() < 1e-9);
        m.check_invariants().unwrap();
    }

    #[test]
    fn a_y_whose_arms_part_at_an_acute_angle_meets_where_its_centrelines_do() {
        // A street 10 wide forks at 30° into two arms 10 wide: the medial
        // axis forks where the corridors separate, about 19 past where the
        // centrelines meet (at the origin); merged, the node is there.
        let (s, c30) = (15f64.to_radians().sin(), 15f64.to_radians().cos());
        let arm =
            |side: f64| geo::LineString::from(vec![c(0., 0.), c(side * 200. * s, 200. * c30)]);
        let trunk = geo::LineString::from(vec![c(0., -200.), c(0., 0.)]);
        use geo::{BooleanOps, Buffer};
        let space = trunk
            .buffer(5.0)
            .union(&arm(1.0).buffer(5.0))
            .union(&arm(-1.0).buffer(5.0));
        let p = PreparedPolygon::new(&space.0[0]).unwrap();
        let g = pruned_axis(&p);
        let fork = |g: &SkeletonGraph| -> Vec<Coord<f64>> {
            let d = g.degrees();
            (0..d.len())
                .filter(|&i| d[i] >= 3)
                .map(|i| g.nodes()[i].pos)
                .collect()
        };
        let before = fork(&g);
        assert_eq!(before.len(), 1);
        assert!(norm(before[0]) > 10.0, "{before:?}");
        let m = merge(&g, &p);
        let after = fork(&m);
        assert_eq!(after.len(), 1, "{after:?}");
        assert!(norm(after[0]) < 1.0, "{after:?}");
        m.check_invariants().unwrap();
    }

    #[test]
    fn a_staggered_crossing_stays_two_junctions_without_crossing_lines() {
        // A street 10 wide (y 47–57) and, one width south, a parallel one
        // (y 36–46) leaving east from a street running south (x −5–5): the
        // two three-way nodes are 10 apart, their discs overlap, but the
        // node where all lines meet would sit on the far rim and the lines
        // from the northern junction would run back through the centre.
        use geo::{BooleanOps, Rect};
        let r = |x0, y0, x1, y1| Rect::new(c(x0, y0), c(x1, y1)).to_polygon();
        let space = r(-60., 47., 60., 57.)
            .union(&r(-5., -60., 5., 57.))
            .union(&r(-5., 36., 60., 46.));
        let p = PreparedPolygon::new(&space.0[0]).unwrap();
        let g = pruned_axis(&p);
        let m = merge(&g, &p);
        m.check_invariants().unwrap();
        let d = m.degrees();
        let junctions: Vec<Coord<f64>> = (0..d.len())
            .filter(|&i| d[i] >= 3)
            .map(|i| m.nodes()[i].pos)
            .collect();
        assert_eq!(junctions.len(), 2, "{junctions:?}");
        // No line doubles back over another.
        let pieces = m.to_multilinestring();
        let mut segments: Vec<(CoordKey, CoordKey)> = pieces
            .0
            .iter()
            .flat_map(|l| l.lines())
            .map(|l| {
                let (a, b) = (CoordKey::from(l.start), CoordKey::from(l.end));
                (a.min(b), a.max(b))
            })
            .collect();
        let n = segments.len();
        segments.sort_unstable();
        segments.dedup();
        assert_eq!(segments.len(), n, "a segment twice: {pieces:?}");
        // Each where its streets' centrelines meet, within a tenth of the width.
        let mut at = junctions.clone();
        at.sort_by(|a, b| b.y.total_cmp(&a.y));
        assert!(norm(at[0] - c(0., 52.)) < 1.0, "{at:?}");
        assert!(norm(at[1] - c(0., 41.)) < 1.0, "{at:?}");
    }

    #[test]
    fn side_streets_a_width_apart_on_a_through_street_stay_two_junctions() {
        // A street 10 wide running north–south, a side street leaving west
        // at y 0–10 and one leaving east at y −10–0: the medial axis has a
        // three-way node for each, 10 apart (their discs touch), but their
        // streets meet at (0, 5) and (0, −5), not at one point.
        let p = PreparedPolygon::new(&polygon![
            (x: -5., y: -60.), (x: 5., y: -60.), (x: 5., y: -10.), (x: 60., y: -10.),
            (x: 60., y: 0.), (x: 5., y: 0.), (x: 5., y: 60.), (x: -5., y: 60.),
            (x: -5., y: 10.), (x: -60., y: 10.), (x: -60., y: 0.), (x: -5., y: 0.)
        ])
        .unwrap();
        let g = pruned_axis(&p);
        let m = merge(&g, &p);
        m.check_invariants().unwrap();
        let d = m.degrees();
        let mut at: Vec<Coord<f64>> = (0..d.len())
            .filter(|&i| d[i] >= 3)
            .map(|i| m.nodes()[i].pos)
            .collect();
        at.sort_by(|a, b| b.y.total_cmp(&a.y));
        assert_eq!(at.len(), 2, "{at:?}");
        assert!(norm(at[0] - c(0., 5.)) < 1.5, "{at:?}");
        assert!(norm(at[1] - c(0., -5.)) < 1.5, "{at:?}");
    }
}
