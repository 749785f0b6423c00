//! Polygon validity (OGC simple-feature rules that matter for skeletons),
//! checked with the boundary's R-tree in O(n log n) so that a polygon of a
//! million vertices is checked in about a second, not hours.
//!
//! A prepared polygon is invalid when two boundary edges cross, overlap, or
//! touch anywhere other than at a single point of two *different* rings (a
//! hole may touch the shell or another hole at a point, as OGC allows); when
//! a ring doubles back on itself (a spike); when a hole lies outside the
//! exterior ring or inside another hole. Each problem is reported with its
//! position so that the user can find it.

use super::segment::{on_segment, orient, BoundarySegment};
use super::vector::{cross, dot};
use super::PreparedPolygon;
use geo::Coord;

fn at(c: Coord<f64>) -> String {
    format!("({}, {})", c.x, c.y)
}

/// What is wrong with segments `s` and `t` (which are not consecutive in one
/// ring), if anything.
fn pair_problem(s: &BoundarySegment, t: &BoundarySegment) -> Option<String> {
    let (o1, o2) = (orient(s.a, s.b, t.a), orient(s.a, s.b, t.b));
    let (o3, o4) = (orient(t.a, t.b, s.a), orient(t.a, t.b, s.b));
    let what = if s.ring == t.ring {
        if s.ring == 0 {
            "the exterior ring"
        } else {
            "a hole"
        }
    } else {
        "two rings"
    };
    if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
        // Proper crossing: report the crossing point.
        let d = s.b - s.a;
        let e = t.b - t.a;
        // Not `lines_meet`: the robust orientations decide the crossing,
        // and a rounded denominator of zero still reports a point.
        let u = cross(t.a - s.a, e) / cross(d, e);
        return Some(format!("{what} cross at {}", at(s.a + d * u)));
    }
    if o1 == 0.0 && o2 == 0.0 {
        // Collinear: an overlap of positive length is invalid.
        let d = s.b - s.a;
        let proj = |p: Coord<f64>| dot(p - s.a, d);
        let l2 = dot(d, d);
        let (lo, hi) = {
            let (x, y) = (proj(t.a), proj(t.b));
            (x.min(y), x.max(y))
        };
        if lo.max(0.0) < hi.min(l2) {
            let p = if (0.0..=l2).contains(&proj(t.a)) {
                t.a
            } else {
                s.a
            };
            return Some(format!("{what} overlap along an edge near {}", at(p)));
        }
    }
    // Touching: an end point of one on the other.
    for (p, seg) in [(t.a, s), (t.b, s), (s.a, t), (s.b, t)] {
        if on_segment(seg.a, seg.b, p) {
            if s.ring != t.ring {
                // OGC: two rings may touch at a point (a vertex of one on
                // the other, anywhere along it); `split_touches` makes such
                // a point a vertex of both before the methods run.
                continue;
            }
            let how = if s.ring == t.ring {
                "touches itself"
            } else {
                "touch"
            };
            let what = if s.ring == t.ring { what } else { "two rings" };
            return Some(format!("{what} {how} at {}", at(p)));
        }
    }
    None
}

/// The first validity problem of `p`, or `None` when it is valid.
pub fn problem(p: &PreparedPolygon) -> Option<String> {
    let b = p.boundary();
    let segs = b.segments();
    let mut ring_len: Vec<u32> = Vec::new();
    for s in segs {
        let r = s.ring as usize;
        if ring_len.len() <= r {
            ring_len.resize(r + 1, 0);
        }
        ring_len[r] += 1;
    }
    let consecutive = |s: &BoundarySegment, t: &BoundarySegment| {
        s.ring == t.ring && {
            let n = ring_len[s.ring as usize];
            (s.index + 1) % n == t.index || (t.index + 1) % n == s.index
        }
    };
    // What is wrong with segments i < j whose boxes meet, if anything.
    let check = |i: usize, j: usize| {
        let (s, t) = (&segs[i], &segs[j]);
        if consecutive(s, t) {
            // A spike: the next edge runs straight back along this one.
            let (shared, far_s, far_t) = if s.b == t.a {
                (s.b, s.a, t.b)
            } else {
                (s.a, s.b, t.a)
            };
            let (u, v) = (far_s - shared, far_t - shared);
            let rings_of_3 = ring_len[s.ring as usize] < 3;
            return (!rings_of_3 && orient(far_s, shared, far_t) == 0.0 && dot(u, v) > 0.0)
                .then(|| format!("spike: the ring doubles back on itself at {}", at(shared)));
        }
        pair_problem(s, t)
    };
    // The first problem along the boundary: of the pair (i, j) first in
    // segment order, so the report does not depend on the tree's layout
    // (nor on the threads that share a long boundary's pairs).
    if let Some((_, _, m)) = b.first_segment_pair(check) {
        return Some(m);
    }
    // With no crossings, a hole lies wholly inside or outside every other ring:
    // test the midpoint of its first edge (never on another ring, since touching
    // edges were rejected above).
    for (hi, hole) in p.polygon().interiors().iter().enumerate() {
        let ring = hi as u32 + 1;
        let m = Coord {
            x: (hole.0[0].x + hole.0[1].x) * 0.5,
            y: (hole.0[0].y + hole.0[1].y) * 0.5,
        };
        if !b.contains_with_rings(m, |r| r == 0) {
            return Some(format!(
                "hole {hi} lies outside the exterior ring (near {})",
                at(m)
            ));
        }
        if b.contains_with_rings(m, |r| r != 0 && r != ring) {
            return Some(format!(
                "hole {hi} lies inside another hole (near {})",
                at(m)
            ));
        }
    }
    None
}

/// `polygon` (normalised, rings closed) with every point where a vertex of
/// one ring lies inside an edge of another ring inserted into that edge, so
/// that rings touching at a point share a vertex there (every method
/// handles a shared vertex; a vertex in the middle of another ring's edge
/// breaks triangulations).
pub fn split_touches(polygon: &geo::Polygon<f64>) -> geo::Polygon<f64> {
    use super::Boundary;
    let rings: Vec<&geo::LineString<f64>> = std::iter::once(polygon.exterior())
        .chain(polygon.interiors())
        .collect();
    if rings.len() < 2 {
        return polygon.clone();
    }
    let b = Boundary::new(polygon);
    // (ring, edge index) → points to insert.
    let mut cuts: std::collections::BTreeMap<(u32, u32), Vec<Coord<f64>>> = Default::default();
    for (r, ring) in rings.iter().enumerate() {
        for &p in &ring.0[..ring.0.len() - 1] {
            for j in b.segments_near(p, p) {
                let s = &b.segments()[j];
                if s.ring as usize != r && p != s.a && p != s.b && on_segment(s.a, s.b, p) {
                    cuts.entry((s.ring, s.index)).or_default().push(p);
                }
            }
        }
    }
    if cuts.is_empty() {
        return polygon.clone();
    }
    let split = |r: usize, ring: &geo::LineString<f64>| {
        let mut out = Vec::with_capacity(ring.0.len() + 2);
        for (i, w) in ring.0.windows(2).enumerate() {
            out.push(w[0]);
            if let Some(ps) = cuts.get(&(r as u32, i as u32)) {
                let d = w[1] - w[0];
                let mut ps = ps.clone();
                ps.sort_by(|p, q| {
                    let t = |c: Coord<f64>| dot(c - w[0], d);
                    t(*p).total_cmp(&t(*q))
                });
                ps.dedup();
                out.extend(ps);
            }
        }
        out.push(ring.0[ring.0.len() - 1]);
        geo::LineString(out)
    };
    geo::Polygon::new(
        split(0, rings[0]),
        rings[1..]
            .iter()
            .enumerate()
            .map(|(k, r)| split(k + 1, r))
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::polygon;

    fn check(p: geo::Polygon<f64>) -> Option<String> {
        problem(&PreparedPolygon::new(&p).unwrap())
    }

    #[test]
    fn a_hole_touching_the_shell_inside_an_edge_is_valid_and_split_there() {
        use geo::polygon;
        let p = polygon!(
            exterior: [(x: 0., y: 0.), (x: 100., y: 0.), (x: 100., y: 100.), (x: 0., y: 100.), (x: 0., y: 0.)],
            interiors: [[(x: 0., y: 50.), (x: 30., y: 40.), (x: 30., y: 60.), (x: 0., y: 50.)]],
        );
        let pp = PreparedPolygon::new(&p).unwrap();
        assert_eq!(problem(&pp), None);
        // The shell got the touching point as a vertex.
        assert!(pp.polygon().exterior().0.contains(&Coord { x: 0., y: 50. }));
    }

    #[test]
    fn valid_polygons_pass() {
        assert_eq!(
            check(polygon![(x: 0., y: 0.), (x: 4., y: 0.), (x: 4., y: 4.), (x: 0., y: 4.)]),
            None
        );
        // A hole touching the exterior at one vertex is valid.
        let p = polygon!(
            exterior: [(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 10.), (x: 0., y: 10.)],
            interiors: [[(x: 0., y: 0.), (x: 4., y: 2.), (x: 2., y: 4.)]],
        );
        assert_eq!(check(p), None);
    }

    /// With several problems, the one reported is that of the first pair of
    /// segments in boundary order, as a scan of every pair finds it — not
    /// whichever the tree's self-join meets first.
    #[test]
    fn the_first_problem_in_boundary_order_is_reported() {
        let n = 400;
        let circle: Vec<Coord<f64>> = (0..n)
            .map(|k| {
                let t = k as f64 / n as f64 * std::f64::consts::TAU;
                Coord {
                    x: 100.0 * t.cos(),
                    y: 100.0 * t.sin(),
                }
            })
            .collect();
        let places = [10, 60, 140, 220, 300, 370];
        for (k, &a) in places.iter().enumerate() {
            for &b in &places[k + 1..] {
                // Two bow-ties far apart along the ring.
                let mut ring = circle.clone();
                ring.swap(a, a + 1);
                ring.swap(b, b + 1);
                let pp = PreparedPolygon::new(&geo::Polygon::new(ring.into(), vec![])).unwrap();
                let segs = pp.boundary().segments();
                let m = segs.len() as u32;
                let mut scan = None;
                'pairs: for i in 0..segs.len() {
                    for j in i + 1..segs.len() {
                        let (s, t) = (&segs[i], &segs[j]);
                        if (s.index + 1) % m == t.index || (t.index + 1) % m == s.index {
                            continue;
                        }
                        if let Some(found) = pair_problem(s, t) {
                            scan = Some(found);
                            break 'pairs;
                        }
                    }
                }
                let got = problem(&pp);
                assert!(
                    got.as_deref().is_some_and(|g| g.contains("cross at")),
                    "{got:?}"
                );
                assert_eq!(got, scan, "bow-ties at {a} and {b}");
            }
        }
    }

    #[test]
    fn problems_are_found_and_located() {
        let bow = polygon![(x: 0., y: 0.), (x: 4., y: 4.), (x: 4., y: 0.), (x: 0., y: 6.)];
        assert!(check(bow).unwrap().contains("cross at"));
        let spike = polygon![(x: 0., y: 0.), (x: 4., y: 0.), (x: 4., y: 4.), (x: 6., y: 4.), (x: 4., y: 4.), (x: 0., y: 4.)];
        let m = check(spike).unwrap();
        assert!(m.contains("spike") || m.contains("touches itself"), "{m}");
        let outside = polygon!(
            exterior: [(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 10.), (x: 0., y: 10.)],
            interiors: [[(x: 20., y: 20.), (x: 22., y: 20.), (x: 22., y: 22.)]],
        );
        assert!(check(outside).unwrap().contains("outside the exterior"));
        let nested = polygon!(
            exterior: [(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 10.), (x: 0., y: 10.)],
            interiors: [
                [(x: 1., y: 1.), (x: 9., y: 1.), (x: 9., y: 9.), (x: 1., y: 9.)],
                [(x: 4., y: 4.), (x: 5., y: 4.), (x: 5., y: 5.)],
            ],
        );
        assert!(check(nested).unwrap().contains("inside another hole"));
        let self_touch = polygon![(x: 0., y: 0.), (x: 10., y: 0.), (x: 5., y: 5.), (x: 10., y: 10.), (x: 0., y: 10.), (x: 5., y: 5.)];
        assert!(check(self_touch).unwrap().contains("touches itself"));
    }
}
