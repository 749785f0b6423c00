//! The split-candidate search of the propagation: for each reflex vertex,
//! the edges its ray may reach (in bands along the ray, widened as the
//! search goes, by the direction classes of `lines`), their split times,
//! and the candidate to queue next. The event loop in `mod.rs` asks it
//! when a reflex vertex is made or its band runs out.

use super::*;

impl Propagation<'_> {
    /// How far reflex vertex `z`'s ray reaches inside P (the bound of its
    /// split candidates), and the length of its first search band.
    pub(super) fn ray_reach(&self, z: VertexId) -> Option<(f64, f64)> {
        let vx = *self.w.v(z);
        let s = vx.vel?;
        let speed = hypot(s);
        let start = vx.start + self.origin;
        let reach = self
            .boundary
            .first_hit(start, s / speed, self.tol, 4.0 * self.extent)
            .map_or(2.0 * self.extent, |h| h.t);
        let (l, r) = (self.w.line(vx.left), self.w.line(vx.right));
        let step = hypot(l.b - l.a).min(hypot(r.b - r.a));
        Some((reach, (2.0 * step).clamp(reach / 4096.0, reach)))
    }

    /// The original edges reflex vertex `z`'s split candidates up to
    /// distance `upto` along its ray are taken from (all, or those near
    /// that part of the ray; with `directed`: without those near it that
    /// cannot be candidates, see [`LineIndex::near_ray`], whose `dense` it
    /// is), and the latest time such a candidate may have.
    /// The lines are written into `into` (cleared first; a buffer reused
    /// from band to band).
    pub(super) fn candidate_lines(
        &self,
        z: VertexId,
        upto: f64,
        directed: Option<&mut bool>,
        into: Vec<LineId>,
    ) -> Option<(Vec<LineId>, f64)> {
        let vx = *self.w.v(z);
        let s = vx.vel?;
        let speed = hypot(s);
        let dir = s / speed;
        let t_max = vx.t0 + upto / speed;
        let lines = match self.search {
            Search::Near(factor) => {
                // Faces of edges whose ends are reflex widen away from the
                // edge: search a margin proportional to the reach.
                let end = vx.start + dir * upto;
                let m = factor * upto + self.tol;
                let env = [
                    vx.start.x.min(end.x) - m,
                    vx.start.y.min(end.y) - m,
                    vx.start.x.max(end.x) + m,
                    vx.start.y.max(end.y) + m,
                ];
                // In any order: the candidates are sorted.
                let mut lines = into;
                lines.clear();
                if let Some(dense) = directed {
                    let band = lines::Band {
                        start: vx.start,
                        t0: vx.t0,
                        vel: s,
                        t_max,
                    };
                    *dense = self.index.near_ray(
                        &self.w.lines,
                        &env,
                        &band,
                        self.tol,
                        *dense,
                        &mut lines,
                    );
                } else {
                    self.index.near(&env, &mut lines);
                }
                lines
            }
            Search::All => {
                let mut lines = into;
                lines.clear();
                lines.extend((0..self.w.lines.len()).map(LineId::from_index));
                lines
            }
        };
        Some((lines, t_max))
    }

    /// Searches the next band of reflex vertex `z`'s ray for split
    /// candidates and appends them to its list; `false` when the ray has
    /// been searched to its end. Bands double in length from twice the
    /// vertex's shorter edge (the exhaustive search has one band, the whole
    /// ray), and a band is searched only when the vertex has tried every
    /// candidate of the bands before and lives to reach the end of the
    /// part searched ([`Propagation::next_candidate`]; the candidates on
    /// edges gone from the wavefront do not count): most reflex vertices of
    /// a rough rim end within their first bands, so their search stays
    /// local where a search of the whole ray (which can cross the polygon)
    /// made the propagation quadratic. A band keeps the candidates that come after
    /// the list's last in time order (earlier ones are past). Fails when all
    /// the polygon's candidates together pass the memory budget.
    pub(super) fn search_band(&mut self, z: VertexId) -> Result<bool, MethodError> {
        let band = &mut self.bands[z.index()];
        if band.searched >= band.reach {
            return Ok(false);
        }
        let upto = match (self.search, band.searched > 0.0) {
            (Search::All, _) => band.reach,
            (Search::Near(_), false) => band.first,
            (Search::Near(_), true) => {
                let next = 2.0 * band.searched;
                if next >= 0.5 * band.reach {
                    band.reach
                } else {
                    next
                }
            }
        };
        band.searched = upto;
        let mut dense = band.dense;
        let scratch = std::mem::take(&mut self.scratch);
        let found = self.candidate_lines(z, upto, Some(&mut dense), scratch);
        self.bands[z.index()].dense = dense;
        let Some((lines, t_max)) = found else {
            return Ok(false);
        };
        self.ctx.check(MethodId::STSK)?;
        self.stats.tried += lines.len();
        let last = self.candidates[z.index()].last().copied();
        let c = split_candidates(&self.w, z, lines.iter().copied(), t_max, self.tol, last);
        self.scratch = lines;
        let list = &mut self.candidates[z.index()];
        self.stats.candidates += c.len();
        list.extend(c);
        if self.stats.candidates > self.max_candidates {
            return Err(MethodError::OverBudget {
                method: MethodId::STSK,
                reason: format!(
                    "needed more than {:.0} MB for the split events of this polygon, more than `skeleton.max_memory_mb`",
                    (self.max_candidates * CANDIDATE_BYTES) as f64 / 1e6
                ),
            });
        }
        Ok(true)
    }

    /// Makes reflex vertex `v`'s candidate `i` known if its ray has one up
    /// to time `until`, searching further bands as needed (a band whose
    /// part of the ray the vertex reaches after `until` holds no candidate
    /// before it).
    pub(super) fn reach_candidate(
        &mut self,
        v: VertexId,
        i: usize,
        until: f64,
    ) -> Result<(), MethodError> {
        while i >= self.candidates[v.index()].len()
            && self.band_end(v).is_none_or(|t| t <= until)
            && self.search_band(v)?
        {}
        Ok(())
    }

    /// The cost of the propagation, predicted from a sample of the input's
    /// reflex vertices: (edges to try, candidates to keep) over all of them,
    /// each as if it searched its whole ray among every edge. That is an
    /// upper estimate: a vertex searches band after band only while it
    /// lives, among the edges still in the wavefront (on a rough rim it ends
    /// early and most edges near it are gone, and a band with many edges
    /// near skips those that cannot be candidates: 280–620× fewer tries
    /// than predicted on the rough polygon of `scripts/make_rough_polygon.py`
    /// at 100 000–200 000 vertices (80× before the search by direction);
    /// about as predicted on a raster staircase; see [`LIKELY_SHARE`]).
    /// The first eighth of the sample is spread over the whole polygon;
    /// when its estimate already makes `hopeless` true (far beyond the
    /// budget), that estimate is returned without the rest — on a huge
    /// polygon each sampled vertex can cost a scan of every edge.
    pub(super) fn predict(&self, hopeless: impl Fn((f64, f64)) -> bool) -> (f64, f64) {
        let reflex: Vec<VertexId> = (0..self.w.vertices.len())
            .map(VertexId::from_index)
            .filter(|&v| self.w.v(v).reflex)
            .collect();
        if reflex.is_empty() {
            return (0.0, 0.0);
        }
        let step = reflex.len().div_ceil(PREDICTION_SAMPLE);
        let sample: Vec<VertexId> = reflex.iter().copied().step_by(step).collect();
        // Every eighth sampled vertex first, then the others.
        let first = sample.iter().step_by(8).copied();
        let rest = sample
            .iter()
            .enumerate()
            .filter(|(i, _)| i % 8 != 0)
            .map(|(_, &z)| z);
        let (mut tried, mut kept, mut sampled) = (0usize, 0usize, 0usize);
        let estimate = |tried: usize, kept: usize, sampled: usize| {
            let scale = reflex.len() as f64 / sampled.max(1) as f64;
            (tried as f64 * scale, kept as f64 * scale)
        };
        let first_count = sample.len().div_ceil(8);
        for z in first.chain(rest) {
            let Some((upto, _)) = self.ray_reach(z) else {
                continue;
            };
            if let Some((lines, t_max)) = self.candidate_lines(z, upto, None, Vec::new()) {
                tried += lines.len();
                kept +=
                    split_candidates(&self.w, z, lines.into_iter(), t_max, self.tol, None).len();
            }
            sampled += 1;
            if sampled == first_count && sampled < sample.len() {
                let partial = estimate(tried, kept, sampled);
                if hopeless(partial) {
                    return partial;
                }
            }
        }
        estimate(tried, kept, sampled)
    }

    /// Queues reflex vertex `v`'s split candidate `i`, or the first after it
    /// whose line is still in the wavefront (on a staircase most original
    /// edges are gone before a vertex's candidate on them comes up).
    pub(super) fn push_candidate(&mut self, v: VertexId, i: u32) -> Result<(), MethodError> {
        if let Some((t, i)) = self.next_candidate(v, i)? {
            self.q.push(t, split(v, i));
        }
        Ok(())
    }

    /// The time and index of the candidate [`Self::push_candidate`] queues.
    /// When the candidates of the bands searched so far are used up and the
    /// vertex reaches the end of the searched part of its ray only later,
    /// the index is one past the list and the time is that later time: the
    /// next band is searched then, if the vertex still lives
    /// ([`Self::searched_on`]), not now.
    pub(super) fn next_candidate(
        &mut self,
        v: VertexId,
        i: u32,
    ) -> Result<Option<(f64, u32)>, MethodError> {
        let mut i = i as usize;
        loop {
            if i >= self.candidates[v.index()].len() {
                if let Some(t) = self.band_end(v).filter(|&t| t > self.now) {
                    return Ok(Some((t, i as u32)));
                }
                if !self.search_band(v)? {
                    return Ok(None);
                }
                continue;
            }
            let c = self.candidates[v.index()][i];
            if self.w.line_alive(c.line) {
                return Ok(Some((c.t.max(self.now), i as u32)));
            }
            i += 1;
        }
    }

    /// When reflex vertex `v` reaches the end of the part of its ray
    /// searched so far (`None` before the first band).
    pub(super) fn band_end(&self, v: VertexId) -> Option<f64> {
        let band = self.bands[v.index()];
        let vx = self.w.v(v);
        let speed = hypot(vx.vel?);
        (band.searched > 0.0).then(|| vx.t0 + band.searched / speed)
    }

    /// Whether the queue's head is a vertex's deferred search (see
    /// [`Self::next_candidate`]); if so, searches the vertex's next band now
    /// and puts its next candidate in the head's place (or takes the head),
    /// and returns `true`. A deferred search is never held or grouped.
    pub(super) fn searched_on(
        &mut self,
        queued: bool,
        v: VertexId,
        candidate: u32,
    ) -> Result<bool, MethodError> {
        if (candidate as usize) < self.candidates[v.index()].len() {
            return Ok(false);
        }
        // Its time has come (it may be up to `tol` after `now` while the
        // events of a time are pulled).
        let next = if self.search_band(v)? {
            self.next_candidate(v, candidate)?
        } else {
            None
        };
        self.follow_with(queued, v, next);
        Ok(true)
    }

    /// Queues vertex `v`'s `next` split candidate (time, index) in place of
    /// the event just handled: at the queue's head when that event is
    /// there (`queued`: one sift instead of a pop and a push), else pushed;
    /// with no next candidate the head is taken.
    pub(super) fn follow_with(&mut self, queued: bool, v: VertexId, next: Option<(f64, u32)>) {
        match (queued, next) {
            (true, Some((t, i))) => self.q.replace_head(t, split(v, i)),
            (true, None) => self.take(true),
            (false, Some((t, i))) => self.q.push(t, split(v, i)),
            (false, None) => {}
        }
    }
}
