//! Generated test shapes, as WKT: workloads whose size a test chooses.

/// A lake (a wavy strip 100 km × 2 km, 2 002 vertices) and one zig-zag line
/// crossing it `crossings` times, as WKT.
pub fn zig_zag_lake(crossings: usize) -> (String, String) {
    let (l, w, m) = (100_000.0, 2_000.0, 1000);
    let top = (0..=m).map(|i| {
        let i = i as f64;
        (l * i / m as f64, w / 2.0 + 150.0 * (i / 37.0).sin())
    });
    let bottom = (0..=m).rev().map(|i| {
        let i = i as f64;
        (l * i / m as f64, -w / 2.0 + 150.0 * (i / 23.0).cos())
    });
    let mut ring: Vec<(f64, f64)> = top.chain(bottom).collect();
    ring.push(ring[0]);
    let k = crossings / 2;
    let line: Vec<(f64, f64)> = (0..=k)
        .map(|i| {
            let x = 500.0 + (l - 1000.0) * i as f64 / k as f64;
            (x, if i % 2 == 0 { 2.0 * w } else { -2.0 * w })
        })
        .collect();
    (
        format!("POLYGON(({}))", coords(&ring)),
        format!("LINESTRING({})", coords(&line)),
    )
}

/// `x y` pairs joined by commas, as WKT wants them.
pub fn coords(pts: &[(f64, f64)]) -> String {
    pts.iter()
        .map(|(x, y)| format!("{x} {y}"))
        .collect::<Vec<_>>()
        .join(",")
}

/// A rough five-lobed lake of `n` vertices (radius 10 km ± 30 %, up to
/// 30 m of pseudo-random radial roughness at every vertex: spiky at the
/// scale of its own vertex spacing). Star-shaped around its centre, so
/// simple at every `n`.
pub fn rough_lobes(n: usize) -> String {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut ring: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let u = (state >> 11) as f64 / (1u64 << 53) as f64;
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            let r = 10_000.0 * (1.0 + 0.3 * (5.0 * t).sin()) + 30.0 * u;
            (500_000.0 + r * t.cos(), 6_000_000.0 + r * t.sin())
        })
        .collect();
    ring.push(ring[0]);
    format!("POLYGON(({}))", coords(&ring))
}

/// A snake: a strip that runs `turns` times across a square of side
/// `side` and back (a square wave of `turns` legs `side / turns` apart,
/// buffered by a quarter of that with mitred corners): 4 × `turns`
/// vertices, and a centre line `turns` times the square's side long.
pub fn snake(turns: usize, side: f64) -> String {
    let d = side / turns as f64;
    let w = d / 4.0;
    let path: Vec<(f64, f64)> = (0..turns)
        .flat_map(|i| {
            let x = d * i as f64;
            match i % 2 {
                0 => [(x, 0.0), (x, side)],
                _ => [(x, side), (x, 0.0)],
            }
        })
        .collect();
    let normal = |p: (f64, f64), q: (f64, f64)| {
        let (dx, dy) = (q.0 - p.0, q.1 - p.1);
        let l = (dx * dx + dy * dy).sqrt();
        (-dy / l, dx / l)
    };
    // Every turn is a right angle: its mitre point is the vertex moved by
    // w along the sum of the two segments' normals.
    let offset = |s: f64| -> Vec<(f64, f64)> {
        (0..path.len())
            .map(|k| {
                let into = (k > 0).then(|| normal(path[k - 1], path[k]));
                let out = (k + 1 < path.len()).then(|| normal(path[k], path[k + 1]));
                let (nx, ny) = match (into, out) {
                    (Some(a), Some(b)) => (a.0 + b.0, a.1 + b.1),
                    (Some(a), None) | (None, Some(a)) => a,
                    (None, None) => (0.0, 0.0),
                };
                (path[k].0 + s * w * nx, path[k].1 + s * w * ny)
            })
            .collect()
    };
    let mut ring = offset(1.0);
    ring.extend(offset(-1.0).into_iter().rev());
    ring.push(ring[0]);
    format!("POLYGON(({}))", coords(&ring))
}

/// A straight river 100 km × 1 km along the x axis and `n` units on each
/// bank (strips 100 km / `n` wide and 4.5 km deep, meeting the banks), as
/// WKT.
pub fn river_between_strips(n: usize) -> (String, Vec<String>) {
    let l = 100_000.0;
    let river = format!(
        "POLYGON(({}))",
        coords(&[
            (0.0, -500.0),
            (l, -500.0),
            (l, 500.0),
            (0.0, 500.0),
            (0.0, -500.0)
        ])
    );
    let units = [(500.0, 5_000.0), (-5_000.0, -500.0)]
        .into_iter()
        .flat_map(|(y0, y1)| {
            (0..n).map(move |i| {
                let (x0, x1) = (l * i as f64 / n as f64, l * (i + 1) as f64 / n as f64);
                format!(
                    "POLYGON(({}))",
                    coords(&[(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)])
                )
            })
        })
        .collect();
    (river, units)
}
