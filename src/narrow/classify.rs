//! The skeleton sampled densely enough to place changes of class within a
//! quarter width, each sample narrow or wide (steps 1–3 of the module
//! documentation).

use super::CollapseParams;
use crate::geometry::vector::norm;
use crate::geometry::{CoordKey, PreparedPolygon};
use crate::graph::{EdgeId, NodeId, SkeletonGraph, UnionFind};
use geo::Coord;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// At most this many samples per polygon part: beyond it, wider spacing.
const MAX_SAMPLES: f64 = 2_000_000.0;

/// The finest spacing of samples, relative to the polygon part's extent: a
/// change of class is placed no finer than this however small `width` is
/// (a width of a micrometre on a lake would otherwise sample it millions of
/// times for nothing: nothing but its tips is that narrow).
const MIN_STEP: f64 = 1e-4;

/// The sampled skeleton: vertices with their radius, segments between them.
pub(super) struct Samples {
    /// Positions.
    pub pos: Vec<Coord<f64>>,
    /// Distance to ∂P.
    pub r: Vec<f64>,
    /// Inserted by the sampling (collinear with the skeleton's own vertices,
    /// so dropped again from the output lines).
    pub inserted: Vec<bool>,
    /// Segments `(a, b, length)`.
    pub segments: Vec<(u32, u32, f64)>,
    /// Segments incident to each sample.
    adj: Vec<Vec<u32>>,
    /// Narrow (collapsed) or wide (kept), per sample.
    pub narrow: Vec<bool>,
    /// The collapse width.
    pub width: f64,
    /// Samples of connection legs, each with the sample where its leg
    /// leaves the skeleton: they take that sample's class.
    follows: Vec<(u32, u32)>,
}

/// The samples of [`Samples::of`] as they are made: the graph's nodes
/// (same numbers), then the points inserted along its edges, edge by edge.
struct Sampling {
    pos: Vec<Coord<f64>>,
    inserted: Vec<bool>,
    segments: Vec<(u32, u32)>,
    follows: Vec<(u32, u32)>,
}

/// The sample of node `n`: its own number.
fn sample(n: NodeId) -> u32 {
    n.index() as u32
}

impl Sampling {
    /// Starts with the nodes of `g`.
    fn of_nodes(g: &SkeletonGraph) -> Self {
        let pos: Vec<Coord<f64>> = g.nodes().iter().map(|n| n.pos).collect();
        Self {
            inserted: vec![false; pos.len()],
            pos,
            segments: Vec::new(),
            follows: Vec::new(),
        }
    }

    /// A new sample at `c`; `inserted` when the sampling made it.
    fn push(&mut self, c: Coord<f64>, inserted: bool) -> u32 {
        self.pos.push(c);
        self.inserted.push(inserted);
        self.pos.len() as u32 - 1
    }

    /// Samples edge `id` of `g` at most `step` apart (its own vertices
    /// kept); when it is one of the connection `legs`, its samples follow
    /// the end where it leaves the skeleton.
    fn edge(&mut self, g: &SkeletonGraph, id: EdgeId, step: f64, legs: &Legs) {
        let edge = g.edge(id);
        let coords = g.edge_coords(id);
        let (first, last) = (coords[0], coords[coords.len() - 1]);
        let attachment = if legs.contains(&(first.into(), last.into())) {
            Some(sample(edge.a))
        } else if legs.contains(&(last.into(), first.into())) {
            Some(sample(edge.b))
        } else {
            None
        };
        let before = self.pos.len();
        let mut prev = sample(edge.a);
        for k in 1..coords.len() {
            let (a, b) = (coords[k - 1], coords[k]);
            let n = (norm(b - a) / step).ceil().max(1.0) as usize;
            for j in 1..n {
                let cur = self.push(super::lerp(a, b, j as f64 / n as f64), true);
                self.segments.push((prev, cur));
                prev = cur;
            }
            let cur = if k == coords.len() - 1 {
                sample(edge.b)
            } else {
                self.push(b, false)
            };
            self.segments.push((prev, cur));
            prev = cur;
        }
        if let Some(a) = attachment {
            let end = if a == sample(edge.a) {
                sample(edge.b)
            } else {
                sample(edge.a)
            };
            let made = before as u32..self.pos.len() as u32;
            self.follows.extend(made.map(|i| (i, a)));
            self.follows.push((end, a));
        }
    }
}

/// The connection legs by their ends (where each leaves the skeleton, its
/// point on the boundary), looked up in constant time per edge.
type Legs = rustc_hash::FxHashSet<(CoordKey, CoordKey)>;

impl Samples {
    /// Samples every edge of `g` at most `width / 4` apart; `legs` are the
    /// connection legs added to `g` (from the skeleton to the boundary).
    pub fn of(
        g: &SkeletonGraph,
        p: &PreparedPolygon,
        width: f64,
        legs: &[(Coord<f64>, Coord<f64>)],
    ) -> Self {
        let total = g.total_length();
        let step = (width / 4.0)
            .max(total / MAX_SAMPLES)
            .max(MIN_STEP * p.extent());
        let mut s = Sampling::of_nodes(g);
        let legs: Legs = legs.iter().map(|&(a, c)| (a.into(), c.into())).collect();
        for e in 0..g.edges().len() {
            s.edge(g, EdgeId::from_index(e), step, &legs);
        }
        let Sampling {
            pos,
            inserted,
            segments,
            follows,
        } = s;
        let boundary = p.boundary();
        let r: Vec<f64> = pos.iter().map(|&c| boundary.distance(c)).collect();
        let segments: Vec<(u32, u32, f64)> = segments
            .into_iter()
            .map(|(a, b)| (a, b, norm(pos[b as usize] - pos[a as usize])))
            .collect();
        let mut adj = vec![Vec::new(); pos.len()];
        for (i, &(a, b, _)) in segments.iter().enumerate() {
            adj[a as usize].push(i as u32);
            adj[b as usize].push(i as u32);
        }
        let n = pos.len();
        Self {
            pos,
            r,
            inserted,
            segments,
            adj,
            narrow: vec![false; n],
            width,
            follows,
        }
    }

    /// Connection legs take the class of the skeleton where they leave it:
    /// they are the network's lines continued, not the polygon's shape (a
    /// leg to a lake's shore is as narrow as the shore, and must neither be
    /// collapsed inside the lake nor cut a notch out of it).
    pub fn follow_legs(&mut self) {
        for &(i, a) in &self.follows {
            self.narrow[i as usize] = self.narrow[a as usize];
        }
    }

    /// Sample `i` lies on some segment.
    fn used(&self, i: usize) -> bool {
        !self.adj[i].is_empty()
    }

    /// Step 1: narrow or wide by the band rule.
    pub fn classify(&mut self, params: &CollapseParams) {
        let w = params.width;
        let (lo, hi) = (w * (1.0 - params.tolerance), w * (1.0 + params.tolerance));
        let strictly_narrow = |d: f64| d < w && d <= lo;
        let strictly_wide = |d: f64| d >= w && d >= hi;
        let d_narrow = self.distances(|i, s| strictly_narrow(2.0 * s.r[i]));
        let d_wide = self.distances(|i, s| strictly_wide(2.0 * s.r[i]));
        // A component wholly inside the band: by its mean width.
        let labels = self.components();
        let mut sums: std::collections::HashMap<usize, (f64, usize)> = Default::default();
        for (&label, &r) in labels.iter().zip(&self.r) {
            let e = sums.entry(label).or_default();
            e.0 += 2.0 * r;
            e.1 += 1;
        }
        for i in 0..self.pos.len() {
            let d = 2.0 * self.r[i];
            self.narrow[i] = if strictly_narrow(d) {
                true
            } else if strictly_wide(d) {
                false
            } else if d_narrow[i].is_finite() || d_wide[i].is_finite() {
                d_narrow[i] <= d_wide[i]
            } else {
                let (sum, n) = sums[&labels[i]];
                sum / (n as f64) < w
            };
        }
    }

    /// Step 2: stretches shorter than `min_length` take their neighbours'
    /// class, shortest first.
    pub fn merge_short(&mut self, min_length: f64) {
        if min_length <= 0.0 {
            return;
        }
        for _ in 0..self.pos.len() {
            let stretches = self.stretches();
            let shortest = stretches
                .iter()
                .filter(|s| s.neighbours && s.length < min_length)
                .min_by(|a, b| a.length.total_cmp(&b.length).then(a.root.cmp(&b.root)));
            let Some(short) = shortest else {
                return;
            };
            let root = short.root;
            let labels = &stretches[0].labels;
            let flip: Vec<usize> = (0..self.pos.len()).filter(|&i| labels[i] == root).collect();
            for i in flip {
                self.narrow[i] = !self.narrow[i];
            }
        }
    }

    /// Step 3 (`mode: whole`): every sample of a component narrow when more
    /// than half of the component's area is, wide otherwise.
    pub fn whole(&mut self) {
        let labels = self.components();
        let mut area: std::collections::HashMap<usize, (f64, f64)> = Default::default();
        for &(a, b, l) in &self.segments {
            let (a, b) = (a as usize, b as usize);
            let w = l * (self.r[a] + self.r[b]);
            let narrow = f64::from(u8::from(self.narrow[a]) + u8::from(self.narrow[b])) / 2.0;
            let e = area.entry(labels[a]).or_default();
            e.0 += w * narrow;
            e.1 += w;
        }
        for (n, label) in self.narrow.iter_mut().zip(&labels) {
            if let Some(&(narrow, total)) = area.get(label) {
                *n = narrow > 0.5 * total;
            }
        }
    }

    /// The segments whose ends differ in class: where the polygon is cut.
    pub fn changes(&self) -> impl Iterator<Item = usize> + '_ {
        self.segments
            .iter()
            .enumerate()
            .filter(|(_, &(a, b, _))| self.narrow[a as usize] != self.narrow[b as usize])
            .map(|(i, _)| i)
    }

    /// Graph distance of every sample to the nearest sample `source` takes
    /// (infinite where none is connected).
    pub fn distances(&self, source: impl Fn(usize, &Self) -> bool) -> Vec<f64> {
        let mut d = vec![f64::INFINITY; self.pos.len()];
        let mut heap = BinaryHeap::new();
        for (i, di) in d.iter_mut().enumerate() {
            if self.used(i) && source(i, self) {
                *di = 0.0;
                heap.push(Reverse((0u64, i as u32)));
            }
        }
        // Non-negative floats order as their bits.
        while let Some(Reverse((bits, i))) = heap.pop() {
            let di = f64::from_bits(bits);
            if di > d[i as usize] {
                continue;
            }
            for &s in &self.adj[i as usize] {
                let (a, b, l) = self.segments[s as usize];
                let j = if a == i { b } else { a };
                let dj = di + l;
                if dj < d[j as usize] {
                    d[j as usize] = dj;
                    heap.push(Reverse((dj.to_bits(), j)));
                }
            }
        }
        d
    }

    /// Component label of every sample.
    fn components(&self) -> Vec<usize> {
        let mut uf = UnionFind::new(self.pos.len());
        for &(a, b, _) in &self.segments {
            uf.union(a as usize, b as usize);
        }
        (0..self.pos.len()).map(|i| uf.find(i)).collect()
    }

    /// The stretches: connected runs of one class, with their length (a
    /// changing segment counts half to each side).
    pub fn stretches(&self) -> Vec<Stretch> {
        let mut uf = UnionFind::new(self.pos.len());
        for &(a, b, _) in &self.segments {
            if self.narrow[a as usize] == self.narrow[b as usize] {
                uf.union(a as usize, b as usize);
            }
        }
        let labels: std::rc::Rc<Vec<usize>> =
            std::rc::Rc::new((0..self.pos.len()).map(|i| uf.find(i)).collect());
        let mut by_root: std::collections::BTreeMap<usize, (f64, bool)> = Default::default();
        for &(a, b, l) in &self.segments {
            let (ra, rb) = (labels[a as usize], labels[b as usize]);
            if ra == rb {
                by_root.entry(ra).or_default().0 += l;
            } else {
                for r in [ra, rb] {
                    let e = by_root.entry(r).or_default();
                    e.0 += l / 2.0;
                    e.1 = true;
                }
            }
        }
        by_root
            .into_iter()
            .map(|(root, (length, neighbours))| Stretch {
                root,
                length,
                neighbours,
                labels: labels.clone(),
            })
            .collect()
    }
}

/// A connected run of samples of one class.
pub(super) struct Stretch {
    /// Its label (a sample of it).
    pub root: usize,
    /// Skeleton length.
    pub length: f64,
    /// It meets a stretch of the other class.
    pub neighbours: bool,
    /// Every sample's stretch label (shared by all stretches).
    pub labels: std::rc::Rc<Vec<usize>>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::GraphBuilder;
    use geo::polygon;

    #[test]
    fn a_tiny_width_samples_no_finer_than_the_polygons_resolution() {
        let t = polygon![(x: 0., y: 0.), (x: 100., y: 0.), (x: 50., y: 80.)];
        let p = PreparedPolygon::new(&t).unwrap();
        let mut b = GraphBuilder::new();
        b.segment(Coord { x: 50., y: 30. }, Coord { x: 0., y: 0. });
        b.segment(Coord { x: 50., y: 30. }, Coord { x: 100., y: 0. });
        b.segment(Coord { x: 50., y: 30. }, Coord { x: 50., y: 80. });
        let g = b.finish(p.boundary());
        let s = Samples::of(&g, &p, 1e-9, &[]);
        // About 170 units of skeleton at 1e-4 × extent (1 cm).
        assert!(s.pos.len() < 20_000, "{} samples", s.pos.len());
        let coarse = Samples::of(&g, &p, 1.0, &[]);
        assert!(
            coarse.pos.len() > 500,
            "a width of 1 still samples every 0.25"
        );
    }
}
