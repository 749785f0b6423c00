//! Like-for-like structure: every method of a feature pruned to the legs of
//! one reference skeleton.
//!
//! The paper compared its methods "with the structure of the skeleton …
//! as the basis for comparison (the number of legs and places of contact
//! point with the outer boundary edge of an object)". Pruned on its own, each
//! method keeps a different number of legs reaching ∂P at different places,
//! so its coverage differs and the highest coverage wins although it comes
//! from spurs. Here one reference skeleton — by default the medial axis,
//! whose radii are exact disc radii, so its pruning measures what it claims,
//! and whose legs end on ∂P — is pruned and extended; its line ends are the
//! **contacts** ([`Structure::of`]). Every other method is then
//! [`conform`]ed to them:
//!
//! 1. **Fragments joined** ([`crate::graph::bridge`]): VD and DVD fall apart
//!    at narrow necks; pieces are joined across gaps of a few local radii.
//! 2. **Terminals.** For a contact c on ∂P, the method's node v whose
//!    inscribed disc comes closest to c: the smallest `|v − c| − r_v` (≥ 0,
//!    and 0 exactly when the disc at v touches ∂P at c), among nodes that see
//!    c without crossing ∂P, searched within 2ρ of c and farther only when
//!    none is found (ρ: the reference's local radius at that end). At a
//!    tapering tip that is the method's own leaf on the tip vertex; at a cut
//!    end it is the node whose disc touches the end side's midpoint. For a
//!    contact inside P (no extension) it is the nearest node. A node on ∂P
//!    serves only the contact it lies on, unless no node inside P sees c: on
//!    a coarse polygon a CDT leaf on the next vertex would otherwise be
//!    joined to c along the shoreline. A terminal alone on its piece of the
//!    method's skeleton while the reference joins c to other contacts (a
//!    crumb beside a tip) is chosen again on the piece that serves the most
//!    of them, when a node there sees c (`rejoin_stranded`).
//! 3. **Peel.** Leaves that are not terminals are removed until none is
//!    left: what stays is the method's own skeleton between its terminals,
//!    with its cycles (holes). With `trunk`, the two terminals of a
//!    component are joined by the method's shortest path between them.
//! 4. **Ends.** Each terminal not yet at its contact is joined to it with a
//!    straight segment (inside v's disc when the disc touches c); where such
//!    a segment or a bridge crosses a line, both get a node there.
//!
//! So every method has the reference's legs, reaching ∂P at the same
//! places, and the metrics decide between like structures.

use super::bridge::bridge;
use super::ends::assemble;
use super::line::{end_radius, point_at};
use super::prune::trunk::shortest_path;
use super::{EdgeId, NodeId, SkeletonGraph, UnionFind};
use crate::geometry::packed::{box_distance_2, Bbox, PackedTree};
use crate::geometry::tolerance::ON_BOUNDARY_END;
use crate::geometry::vector::hypot;
use crate::geometry::PreparedPolygon;
use geo::Coord;
use std::ops::ControlFlow;

/// Where a reference line ends.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    /// The end point.
    pub point: Coord<f64>,
    /// Local radius of the reference at that end: the distance to ∂P one
    /// local width back along the line (see [`end_radius`]).
    pub radius: f64,
    /// The end lies on ∂P.
    pub on_boundary: bool,
    /// Connected component of the reference that the end belongs to.
    pub component: usize,
    /// The reference line from the end back to its first junction (or its
    /// other end): where to look for a terminal when no node sees the end.
    pub approach: Vec<Coord<f64>>,
}

/// The structure every method of one polygon is pruned to.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Structure {
    /// The reference's line ends, in node order.
    pub contacts: Vec<Contact>,
    /// One line per component (`trunk` pruning): terminals are joined by a
    /// shortest path instead of keeping everything between them.
    pub trunk: bool,
}

impl Structure {
    /// The structure of a finished reference skeleton: its leaves.
    pub fn of(reference: &SkeletonGraph, polygon: &PreparedPolygon, trunk: bool) -> Self {
        let tol = ON_BOUNDARY_END * polygon.extent();
        let deg = reference.degrees();
        let labels = reference.component_labels();
        let adj = reference.adjacency();
        let contacts = (0..reference.nodes().len())
            .filter(|&n| deg[n] == 1)
            .map(|n| {
                let node = reference.node(NodeId::from_index(n));
                let approach = reference.line_from(NodeId::from_index(n), &adj);
                Contact {
                    point: node.pos,
                    radius: end_radius(&approach, polygon),
                    on_boundary: polygon.boundary().distance(node.pos) <= tol,
                    component: labels[n],
                    approach,
                }
            })
            .collect();
        Self { contacts, trunk }
    }
}

/// Prunes `raw` (one method's raw skeleton of `polygon`) to `structure`
/// (see the module documentation).
pub fn conform(
    raw: &SkeletonGraph,
    structure: &Structure,
    polygon: &PreparedPolygon,
) -> SkeletonGraph {
    let g = bridge(raw, polygon);
    if g.is_empty() {
        return g;
    }
    let tol = ON_BOUNDARY_END * polygon.extent();
    let tree = NodeIndex::new(&g);
    let serve = |c: &Contact, allowed: &dyn Fn(usize) -> bool| {
        // A node on ∂P away from c would join c along or across the
        // shoreline (a coarse polygon's CDT leaf on the next vertex):
        // such nodes serve c only when no node inside P can.
        terminal(&g, &tree, c, polygon, tol, false, allowed)
            .or_else(|| terminal(&g, &tree, c, polygon, tol, true, allowed))
    };
    let mut served: Vec<Option<(NodeId, bool)>> = structure
        .contacts
        .iter()
        .map(|c| serve(c, &|_| true))
        .collect();
    rejoin_stranded(&g, structure, &mut served, &serve);
    let terminals: Vec<Option<NodeId>> = served.iter().map(|t| t.map(|t| t.0)).collect();
    let mut is_terminal = vec![false; g.nodes().len()];
    for t in terminals.iter().flatten() {
        is_terminal[t.index()] = true;
    }
    let mut keep = peel(&g, &is_terminal);
    if structure.trunk {
        keep = trunk_paths(&g, keep, structure, &terminals);
    }
    let segments: Vec<(NodeId, Coord<f64>)> = structure
        .contacts
        .iter()
        .zip(&served)
        .filter_map(|(c, t)| {
            let (t, sees) = (*t)?;
            if !sees {
                return None;
            }
            let p = g.node(t).pos;
            let d = hypot(p - c.point);
            (c.on_boundary && d > tol).then_some((t, c.point))
        })
        .collect();
    let out = assemble(&g, &keep, &segments);
    super::planar::node_crossings(out, polygon.boundary()).0
}

/// Finds the node serving a contact among the nodes a filter allows, and
/// whether it sees the contact (see [`terminal`]).
type ServeContact<'a> = dyn Fn(&Contact, &dyn Fn(usize) -> bool) -> Option<(NodeId, bool)> + 'a;

/// Serves again, from the method's piece that serves the others, each
/// contact whose terminal lies alone on a piece of the method's skeleton
/// while the reference joins it to other contacts. Peeling would leave such
/// a terminal without a line, and the reference's line to it would be
/// lost: on a river vectorised from a raster, DVD's leaf nearest a tip can
/// sit on a crumb of a few metres beside the skeleton (the 193 km line
/// became 76 m). The piece kept is the one serving the most contacts of
/// that reference component (the longer on a tie); a contact that no node
/// of it sees (the segment to the contact would leave P) keeps its
/// terminal. A method whose skeleton falls apart into
/// pieces that each serve several contacts is left as it is.
fn rejoin_stranded(
    g: &SkeletonGraph,
    structure: &Structure,
    served: &mut [Option<(NodeId, bool)>],
    serve: &ServeContact<'_>,
) {
    let label = g.component_labels();
    let mut length = vec![0.0; g.nodes().len()];
    for (i, e) in g.edges().iter().enumerate() {
        length[label[e.a.index()]] += g.edge_length(EdgeId::from_index(i));
    }
    // Per reference component: terminals per piece of the method's skeleton.
    let mut count: std::collections::BTreeMap<(usize, usize), usize> = Default::default();
    for (c, t) in structure.contacts.iter().zip(served.iter()) {
        if let Some((t, _)) = t {
            *count.entry((c.component, label[t.index()])).or_default() += 1;
        }
    }
    // Per reference component: the piece serving the most of its contacts
    // (the longer, then the lower label, on a tie).
    let mut main: std::collections::BTreeMap<usize, usize> = Default::default();
    for (&(k, piece), &n) in &count {
        let better = main.get(&k).is_none_or(|&m| {
            (n, length[piece]).partial_cmp(&(count[&(k, m)], length[m]))
                == Some(std::cmp::Ordering::Greater)
        });
        if better {
            main.insert(k, piece);
        }
    }
    for (i, c) in structure.contacts.iter().enumerate() {
        let Some((t, _)) = served[i] else { continue };
        let piece = label[t.index()];
        let Some(&m) = main.get(&c.component) else {
            continue;
        };
        if piece == m || count[&(c.component, piece)] > 1 {
            continue;
        }
        if let Some(again @ (_, true)) = serve(c, &|n| label[n] == m) {
            served[i] = Some(again);
        }
    }
}

/// The nodes of a graph by position, for the searches around each contact.
struct NodeIndex {
    /// Each node's point as a box, in node order.
    boxes: Vec<Bbox>,
    /// A tree over them when there are many.
    tree: Option<PackedTree>,
}

/// At most this many nodes are scanned instead of searched in a tree: a
/// handful of searches per contact cost less than building one (most
/// islands' skeletons).
const FEW_NODES: usize = 128;

impl NodeIndex {
    fn new(g: &SkeletonGraph) -> Self {
        let boxes: Vec<Bbox> = g
            .nodes()
            .iter()
            .map(|n| [n.pos.x, n.pos.y, n.pos.x, n.pos.y])
            .collect();
        let tree = (boxes.len() > FEW_NODES).then(|| PackedTree::new(&boxes));
        Self { boxes, tree }
    }

    /// Every node within squared distance `r2` of `q` (a node's box is its
    /// point, so the box distance is the point's squared distance, bit for
    /// bit), in no particular order.
    fn within(&self, q: Coord<f64>, r2: f64, mut f: impl FnMut(u32)) {
        let near = |bx: &Bbox| box_distance_2(bx, q.x, q.y) <= r2;
        match &self.tree {
            Some(tree) => {
                tree.visit(near, |n| {
                    f(n);
                    ControlFlow::<()>::Continue(())
                });
            }
            None => {
                for (n, bx) in self.boxes.iter().enumerate() {
                    if near(bx) {
                        f(n as u32);
                    }
                }
            }
        }
    }
}

/// The node of `g` that serves contact `c` (see the module documentation),
/// and whether it sees `c`. When no node sees `c` (the reference runs into
/// a channel too narrow for this method's skeleton), the node that sees the
/// reference line farthest along its approach to `c` serves it. Nodes on
/// ∂P (radius within `tol`) other than at `c` itself count only with
/// `on_boundary`.
fn terminal(
    g: &SkeletonGraph,
    tree: &NodeIndex,
    c: &Contact,
    polygon: &PreparedPolygon,
    tol: f64,
    on_boundary: bool,
    allowed: &dyn Fn(usize) -> bool,
) -> Option<(NodeId, bool)> {
    let b = polygon.boundary();
    let limit = 4.0 * polygon.extent();
    let score = |d: f64, r: f64| if c.on_boundary { d - r } else { d };
    if let Some(n) = best_seeing(
        g,
        tree,
        c.point,
        (2.0 * c.radius).max(1e3 * tol),
        limit,
        tol,
        &score,
        b,
        (on_boundary, allowed),
    ) {
        return Some((n, true));
    }
    // Points back along the reference line, at doubling arc lengths.
    let total = super::polyline_length(&c.approach);
    let mut s = (c.radius).max(1e3 * tol);
    while s < total {
        let p = point_at(&c.approach, s);
        let r = b.distance(p);
        let near = |d: f64, _: f64| d;
        if let Some(n) = best_seeing(
            g,
            tree,
            p,
            2.0 * r.max(tol),
            2.0 * r.max(tol),
            tol,
            &near,
            b,
            (on_boundary, allowed),
        ) {
            return Some((n, false));
        }
        s *= 2.0;
    }
    None
}

/// The node with the smallest `score(distance, radius)` among those that see
/// `q` (the segment to it stays in P), searched within `start` of `q` and
/// four times farther each round up to `limit`; without `on_boundary`,
/// nodes on ∂P farther than `tol` from `q` are passed over, and so are the
/// nodes `allowed` refuses.
#[allow(clippy::too_many_arguments)]
fn best_seeing(
    g: &SkeletonGraph,
    tree: &NodeIndex,
    q: Coord<f64>,
    start: f64,
    limit: f64,
    tol: f64,
    score: &dyn Fn(f64, f64) -> f64,
    b: &crate::geometry::Boundary,
    (on_boundary, allowed): (bool, &dyn Fn(usize) -> bool),
) -> Option<NodeId> {
    let mut reach = start;
    loop {
        // Candidates in order of (score, distance, node); the first that
        // sees q is the answer, so the costly visibility test runs only
        // until then.
        // Every node at most `reach` from q.
        let r2 = reach * reach;
        let mut keys: Vec<(f64, f64, u32)> = Vec::new();
        tree.within(q, r2, |n| {
            if !allowed(n as usize) {
                return;
            }
            let node = g.node(NodeId::from_index(n as usize));
            let d = hypot(node.pos - q);
            keys.push((score(d, node.radius), d, n));
        });
        keys.sort_unstable_by(|a, b| {
            a.0.total_cmp(&b.0)
                .then(a.1.total_cmp(&b.1))
                .then(a.2.cmp(&b.2))
        });
        let seen = keys.into_iter().find(|&(_, d, n)| {
            let node = g.node(NodeId::from_index(n as usize));
            d <= tol || ((on_boundary || node.radius > tol) && b.reaches(node.pos, q))
        });
        if let Some((_, _, n)) = seen {
            return Some(NodeId::from_index(n as usize));
        }
        if reach >= limit {
            return None;
        }
        reach = (reach * 4.0).min(limit);
    }
}

/// Kept edges after removing, repeatedly, every leaf that is not a terminal.
fn peel(g: &SkeletonGraph, is_terminal: &[bool]) -> Vec<bool> {
    let adj = g.adjacency();
    let mut keep = vec![true; g.edges().len()];
    let mut deg: Vec<usize> = adj.iter().map(<[EdgeId]>::len).collect();
    // Loops count twice in `adj` and never make a leaf.
    let mut stack: Vec<usize> = (0..deg.len())
        .filter(|&n| deg[n] == 1 && !is_terminal[n])
        .collect();
    while let Some(n) = stack.pop() {
        if deg[n] != 1 || is_terminal[n] {
            continue;
        }
        let Some(&e) = adj[n].iter().find(|e| keep[e.index()]) else {
            continue;
        };
        keep[e.index()] = false;
        deg[n] -= 1;
        let o = g.opposite(e, NodeId::from_index(n)).index();
        deg[o] -= 1;
        if deg[o] == 1 && !is_terminal[o] {
            stack.push(o);
        }
    }
    keep
}

/// With `trunk`: in every kept component that holds the two terminals of one
/// reference component, only the shortest path between them.
fn trunk_paths(
    g: &SkeletonGraph,
    keep: Vec<bool>,
    structure: &Structure,
    terminals: &[Option<NodeId>],
) -> Vec<bool> {
    let mut uf = UnionFind::new(g.nodes().len());
    for (i, e) in g.edges().iter().enumerate() {
        if keep[i] {
            uf.union(e.a.index(), e.b.index());
        }
    }
    let mut by_component: std::collections::BTreeMap<usize, Vec<NodeId>> = Default::default();
    for (c, t) in structure.contacts.iter().zip(terminals) {
        if let Some(t) = t {
            by_component.entry(c.component).or_default().push(*t);
        }
    }
    let mut out = keep.clone();
    for ts in by_component.values() {
        let [a, b] = ts[..] else { continue };
        let comp = uf.find(a.index());
        if a == b || uf.find(b.index()) != comp {
            continue;
        }
        let Some(path) = shortest_path(g, &keep, a, b) else {
            continue;
        };
        for (i, e) in g.edges().iter().enumerate() {
            if keep[i] && uf.find(e.a.index()) == comp {
                out[i] = false;
            }
        }
        for e in path {
            out[e.index()] = true;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A river reach from a cut end at x = 0 to a tip at x = 1000, and a
    /// method's skeleton of it: a line from x = 20 to 700, and a crumb of
    /// 2 m beside the tip, too far to be bridged. The crumb's node comes
    /// closest to the tip's contact, but the reference joins the tip to the
    /// cut end: the tip is served from the line, which reaches both ends
    /// as one piece (before, each end kept only its end segment).
    #[test]
    fn a_crumb_beside_a_tip_does_not_cost_the_line() {
        let c = |x: f64, y: f64| Coord { x, y };
        let ring = [(0., 0.), (900., 0.), (1000., 50.), (900., 100.), (0., 100.)];
        let ring: Vec<Coord<f64>> = ring.iter().map(|&(x, y)| c(x, y)).collect();
        let polygon = PreparedPolygon::new(&geo::Polygon::new(ring.into(), vec![])).unwrap();
        let b = polygon.boundary();
        let mut raw = SkeletonGraph::new();
        let node =
            |g: &mut SkeletonGraph, x: f64| g.add_node(c(x, 50.), b.distance(c(x, 50.)), None);
        let (l0, l1, l2) = (
            node(&mut raw, 20.),
            node(&mut raw, 400.),
            node(&mut raw, 700.),
        );
        raw.add_edge(l0, l1, vec![]);
        raw.add_edge(l1, l2, vec![]);
        let (k0, k1) = (node(&mut raw, 984.), node(&mut raw, 986.));
        raw.add_edge(k0, k1, vec![]);
        let contact = |x: f64, radius: f64| Contact {
            point: c(x, 50.),
            radius,
            on_boundary: true,
            component: 0,
            approach: vec![c(x, 50.), c(1000. - x, 50.)],
        };
        let structure = Structure {
            contacts: vec![contact(0., 50.), contact(1000., 30.)],
            trunk: false,
        };
        let out = conform(&raw, &structure, &polygon);
        assert_eq!(out.components(), 1);
        let len = out.total_length();
        assert!((len - 1000.).abs() < 1e-6, "{len}");
        for x in [0., 1000.] {
            assert!(
                out.nodes().iter().any(|n| hypot(n.pos - c(x, 50.)) < 1e-9),
                "no end at x = {x}"
            );
        }
    }

    /// The nodes around a point are the same whether scanned (a small
    /// graph) or found through the tree (a large one).
    #[test]
    fn nodes_within_a_distance_by_scan_or_tree() {
        for n in [1, 7, FEW_NODES, FEW_NODES + 1, 700] {
            let mut g = SkeletonGraph::new();
            for i in 0..n {
                let a = i as f64 * 0.37;
                let pos = Coord {
                    x: a.cos() * (i % 19) as f64,
                    y: a.sin() * (i % 23) as f64,
                };
                g.add_node(pos, 1.0, None);
            }
            let index = NodeIndex::new(&g);
            assert_eq!(index.tree.is_some(), n > FEW_NODES);
            for k in 0..40 {
                let q = Coord {
                    x: (k % 9) as f64 * 2.0 - 8.0,
                    y: (k % 7) as f64 * 2.5 - 7.0,
                };
                let r2 = (k % 5) as f64 * 6.0;
                let mut got = Vec::new();
                index.within(q, r2, |i| got.push(i));
                got.sort_unstable();
                let want: Vec<u32> = (0..n as u32)
                    .filter(|&i| {
                        let p = g.node(NodeId::from_index(i as usize)).pos;
                        (p.x - q.x).powi(2) + (p.y - q.y).powi(2) <= r2
                    })
                    .collect();
                assert_eq!(got, want, "{n} nodes, around {q:?}");
            }
        }
    }
}
