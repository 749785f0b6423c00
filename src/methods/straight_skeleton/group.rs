//! Groups of events at one time and place: an edge or split event alone,
//! several events a vertex event — which chains of the wavefront meet
//! there, how their rays pair up, and how the chains are relinked
//! (the event loop in the parent module hands each group here).

use super::*;

impl Propagation<'_> {
    /// Handles the valid event `ev` (popped at time `now`) together with
    /// every other valid event within `tol` of the same time and point:
    /// one event alone is an edge or split event, several form a vertex
    /// event (see [`Self::vertex_event`]).
    pub(super) fn event_group(&mut self, ev: events::Event) -> Result<(), MethodError> {
        let t0 = self.now;
        let p0 = match ev.kind {
            EventKind::Edge { x, y } => (self.w.pos(x, t0) + self.w.pos(y, t0)) * 0.5,
            EventKind::Split { v, .. } => self.w.pos(v, t0),
        };
        let mut group = vec![ev];
        while self.q.peek_time().is_some_and(|t| t <= t0 + self.tol) {
            if self.head_missed(t0 + self.tol)? {
                continue;
            }
            let Some(e) = self.q.pop() else { break };
            let Some((p, r)) = self.event_place(&e) else {
                continue;
            };
            self.held.hold(e, [p.x, p.y], r, 16.0 * self.tol);
        }
        for placed in self.held.take_at([p0.x, p0.y]) {
            let e = placed.0;
            let here = match e.kind {
                EventKind::Edge { x, y } => {
                    if !self.edge_valid(x, y) {
                        continue;
                    }
                    self.at(x, p0) && self.at(y, p0)
                }
                EventKind::Split { v, .. } => {
                    if !self.w.v(v).active {
                        continue;
                    }
                    self.at(v, p0)
                }
            };
            if here {
                group.push(e);
            } else {
                self.held.put_back(placed);
            }
        }
        // A lone split's piece, found once: whether it meets a vertex, and
        // the piece it cuts when it does not (a refused vertex event changes
        // nothing).
        let lone_piece = match ev.kind {
            EventKind::Split { v, candidate } if group.len() == 1 => {
                let line = self.candidates[v.index()][candidate as usize].line;
                self.find_piece(v, line)
            }
            _ => None,
        };
        let meets_a_vertex = lone_piece.is_some_and(|x| self.at_piece_end(x, p0));
        if (group.len() > 1 || meets_a_vertex) && self.vertex_event(&group, p0)? {
            return Ok(());
        }
        // A single event, or a group whose wavefront pieces do not form a
        // consistent vertex event: the first event alone, the others later.
        for e in &group[1..] {
            self.q.push(e.t, e.kind);
        }
        match ev.kind {
            EventKind::Edge { x, y } => self.edge_event(x, y),
            EventKind::Split { v, candidate } => {
                let c = self.candidates[v.index()][candidate as usize];
                let piece = if group.len() == 1 {
                    lone_piece
                } else {
                    self.find_piece(v, c.line)
                };
                match piece {
                    Some(x) => self.split_event(v, x, c.line),
                    None => self.push_candidate(v, candidate + 1),
                }
            }
        }
    }

    /// Whether the wavefront piece starting at `x` has an end at `p0`: a
    /// lone split there is a reflex vertex meeting a vertex, which is a
    /// vertex event (cutting the piece there would leave a zero-length
    /// piece between two vertices moving as one, and their arcs would
    /// overlap all the way to their next event).
    pub(super) fn at_piece_end(&self, x: VertexId, p0: Coord<f64>) -> bool {
        self.at(x, p0) || self.at(self.w.v(x).next, p0)
    }

    /// Takes the queue's head when it is a split candidate of an active
    /// vertex that finds no piece of its line at its time, and queues the
    /// vertex's next candidate in its place; `true` when it did. The
    /// vertex's next candidates up to time `until` (the end of the events
    /// being pulled) are checked at once, the same way.
    ///
    /// Called on the events of the time being handled before they are held
    /// by place: on a raster staircase nearly all of them are such misses
    /// (a vertex on the pixel grid reaches the lines of the pixel edges
    /// across the river at multiples of half a pixel, and most of those
    /// edges are elsewhere), and holding each by place only to find later
    /// that it misses cost more than the propagation's real events. Deciding
    /// the miss now rather than when the event's turn comes is the same
    /// answer: at one time, the events handled in between change the points
    /// covered by a line's pieces only at their own points (a cut piece
    /// still covers its point, a new piece starts at its event's point), and
    /// a candidate at such a point was checked in that event's group before
    /// the group changed anything — on the same wavefront as now.
    pub(super) fn head_missed(&mut self, until: f64) -> Result<bool, MethodError> {
        let Some(&events::Event {
            t,
            kind: EventKind::Split { v, candidate },
            ..
        }) = self.q.peek()
        else {
            return Ok(false);
        };
        if !self.w.v(v).active {
            return Ok(false);
        }
        if self.searched_on(true, v, candidate)? {
            return Ok(true);
        }
        let (mut t, mut i) = (t, candidate);
        loop {
            let c = self.candidates[v.index()][i as usize];
            if self.find_piece_at(v, c.line, self.now.max(t)).is_some() {
                if i == candidate {
                    return Ok(false);
                }
                // Pulled in its turn, found again and held.
                self.q.replace_head(t, split(v, i));
                return Ok(true);
            }
            self.stats.pops += 1;
            self.stats.missed += 1;
            match self.next_candidate(v, i + 1)? {
                // Its turn comes in this same pull, with the wavefront as it
                // is now: checked at once, without a trip through the queue
                // (a deferred search goes back to the queue).
                Some((next, j))
                    if next <= until && (j as usize) < self.candidates[v.index()].len() =>
                {
                    (t, i) = (next, j)
                }
                Some((next, j)) => {
                    self.q.replace_head(next, split(v, j));
                    return Ok(true);
                }
                None => {
                    self.take(true);
                    return Ok(true);
                }
            }
        }
    }

    /// Several events at one time and point `p0`: every wavefront vertex
    /// involved (and every neighbour already at `p0`) ends there, every
    /// wavefront edge a reflex vertex reaches is cut at `p0`, and the
    /// wavefront is re-linked around `p0`. Each maximal chain of involved
    /// consecutive vertices (or a cut edge) arrives along one line and
    /// leaves along another; sorted by angle around `p0`, arriving and
    /// leaving directions alternate, and each arriving line is joined to
    /// the next leaving line clockwise by one new vertex (none when both
    /// are the same line). Edges between involved vertices have zero
    /// length and vanish. Returns `false` (and changes nothing) when the
    /// directions do not alternate.
    pub(super) fn vertex_event(
        &mut self,
        group: &[events::Event],
        p0: Coord<f64>,
    ) -> Result<bool, MethodError> {
        let t0 = self.now;
        let (inv, cuts, next_candidates) = self.involved(group, p0, t0)?;
        let chains = self.chains(&inv, &cuts);
        let Some(pairs) = self.pair_rays(&chains) else {
            return Ok(false);
        };
        for (v, i) in next_candidates {
            self.push_candidate(v, i)?;
        }
        for &u in &inv {
            self.finish(u, p0);
        }
        self.relink(&pairs, &chains, p0, t0)?;
        Ok(true)
    }

    /// The vertices a vertex event at `p0` involves (sorted), the wavefront
    /// pieces split there (vertex before the cut, line), and the split
    /// candidates to try later.
    #[allow(clippy::type_complexity)]
    pub(super) fn involved(
        &mut self,
        group: &[events::Event],
        p0: Coord<f64>,
        t0: f64,
    ) -> Result<(Vec<VertexId>, Vec<(VertexId, LineId)>, Vec<(VertexId, u32)>), MethodError> {
        let mut inv: Vec<VertexId> = Vec::new();
        let mut cuts: Vec<(VertexId, LineId)> = Vec::new();
        let mut next_candidates = Vec::new();
        for e in group {
            match e.kind {
                EventKind::Edge { x, y } => inv.extend([x, y]),
                EventKind::Split { v, candidate } => {
                    let mut i = candidate as usize;
                    let mut hit = false;
                    loop {
                        self.reach_candidate(v, i, t0 + self.tol)?;
                        let Some(&c) = self.candidates[v.index()].get(i) else {
                            break;
                        };
                        if i > candidate as usize && c.t > t0 + self.tol {
                            break;
                        }
                        if let Some(x) = self.find_piece(v, c.line) {
                            hit = true;
                            let y = self.w.v(x).next;
                            if self.at(x, p0) {
                                inv.push(x);
                            } else if self.at(y, p0) {
                                inv.push(y);
                            } else {
                                cuts.push((x, c.line));
                            }
                        }
                        i += 1;
                    }
                    if hit {
                        inv.push(v);
                    } else {
                        next_candidates.push((v, i as u32));
                    }
                }
            }
        }
        let mut k = 0;
        while k < inv.len() {
            let u = inv[k];
            for n in [self.w.v(u).prev, self.w.v(u).next] {
                if !inv.contains(&n) && self.at(n, p0) {
                    inv.push(n);
                }
            }
            k += 1;
        }
        inv.sort_unstable();
        inv.dedup();
        cuts.sort_unstable_by_key(|c| c.0);
        cuts.dedup_by_key(|c| c.0);
        let is_inv = |v: VertexId| inv.binary_search(&v).is_ok();
        cuts.retain(|c| !is_inv(c.0) && !is_inv(self.w.v(c.0).next));
        Ok((inv, cuts, next_candidates))
    }

    /// The wavefront chains meeting at the event: (arriving line, leaving
    /// line, vertex before, vertex after), one per run of involved vertices
    /// and one per cut piece.
    pub(super) fn chains(
        &self,
        inv: &[VertexId],
        cuts: &[(VertexId, LineId)],
    ) -> Vec<(LineId, LineId, VertexId, VertexId)> {
        let is_inv = |v: VertexId| inv.binary_search(&v).is_ok();
        let mut chains = Vec::new();
        for &u in inv {
            let pred = self.w.v(u).prev;
            if is_inv(pred) {
                continue;
            }
            let mut w = u;
            while is_inv(self.w.v(w).next) {
                w = self.w.v(w).next;
            }
            chains.push((self.w.v(u).left, self.w.v(w).right, pred, self.w.v(w).next));
        }
        for &(x, l) in cuts {
            chains.push((l, l, x, self.w.v(x).next));
        }
        chains
    }

    /// Pairs each chain's arriving ray with the chain whose leaving ray comes
    /// next by angle around the event (`None` when they do not alternate).
    ///
    /// Rays in one direction (within [`FOLD_EPS`], the test for
    /// antiparallel lines) are tied whatever their rounded angles say, and
    /// a tie is tried with its leaving rays first, then last: where two
    /// antiparallel lines meet along a segment (a star's opposite edges
    /// tangent to one circle), the arriving ray of one and the leaving ray
    /// of the other point the same way, and only one order alternates —
    /// the one that joins the two lines into a fold.
    pub(super) fn pair_rays(
        &self,
        chains: &[(LineId, LineId, VertexId, VertexId)],
    ) -> Option<Vec<(usize, usize)>> {
        let angle = |d: Coord<f64>| d.y.atan2(d.x);
        // (angle, leaving, chain, direction)
        let mut rays: Vec<(f64, bool, usize, Coord<f64>)> = Vec::with_capacity(2 * chains.len());
        for (i, &(a, b, _, _)) in chains.iter().enumerate() {
            let arriving = self.w.line(a).dir * -1.0;
            let leaving = self.w.line(b).dir;
            rays.push((angle(arriving), false, i, arriving));
            rays.push((angle(leaving), true, i, leaving));
        }
        rays.sort_by(|r, s| r.0.total_cmp(&s.0));
        let m = rays.len();
        // Each ray's key: the angle of the first ray of its run of rays in
        // one direction; a run at the end that points where the first ray
        // does (across ±π) joins the first run.
        let same = |r: &(f64, bool, usize, Coord<f64>), s: &(f64, bool, usize, Coord<f64>)| {
            1.0 - dot(r.3, s.3) < FOLD_EPS
        };
        let mut key = vec![0.0; m];
        let mut first = 0;
        for i in 0..m {
            if !same(&rays[first], &rays[i]) {
                first = i;
            }
            key[i] = rays[first].0;
        }
        let mut last = m;
        while last > 0 && same(&rays[last - 1], &rays[0]) && key[last - 1] != key[0] {
            last -= 1;
            key[last] = key[0];
        }
        let mut rays: Vec<(f64, bool, usize)> =
            (0..m).map(|i| (key[i], rays[i].1, rays[i].2)).collect();
        for leaving_first in [true, false] {
            rays.sort_by(|r, s| {
                r.0.total_cmp(&s.0).then(if leaving_first {
                    s.1.cmp(&r.1)
                } else {
                    r.1.cmp(&s.1)
                })
            });
            if (0..m).all(|i| rays[i].1 != rays[(i + 1) % m].1) {
                return Some(
                    (0..m)
                        .filter(|&i| !rays[i].1)
                        .map(|i| (rays[i].2, rays[(i + m - 1) % m].2))
                        .collect(),
                );
            }
        }
        None
    }

    /// Links the wavefront anew around the event at `p0`.
    pub(super) fn relink(
        &mut self,
        pairs: &[(usize, usize)],
        chains: &[(LineId, LineId, VertexId, VertexId)],
        p0: Coord<f64>,
        t0: f64,
    ) -> Result<(), MethodError> {
        for &(i, j) in pairs {
            let (a, _, pred, _) = chains[i];
            let (_, b, _, succ) = chains[j];
            if pred == succ && a != b {
                // A triangle collapses to the event point.
                self.finish(pred, p0);
            } else if a == b {
                self.w.link(pred, succ);
                if pred == succ {
                    // A single vertex left: settled (ended) from the work list.
                    self.work.push(pred);
                }
                if let Some(te) = edge_collapse_time(&self.w, pred, succ, t0) {
                    self.q.push(te, EventKind::Edge { x: pred, y: succ });
                }
            } else {
                let m = self.new_vertex(p0, a, b)?;
                self.w.link(pred, m);
                self.w.link(m, succ);
            }
        }
        Ok(())
    }
}
