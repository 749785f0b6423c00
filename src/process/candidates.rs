//! Every method's candidate skeleton of one feature, or a given skeleton's:
//! skeletons part by part, the reference's structure, pruning, extension,
//! scores, bars and widths.

use super::{CandidateError, CandidateSkeleton, ProcessParams, StageTimes};
use crate::clock::{CpuClock, Stage, Stages, Stopwatch};
use crate::geometry::PreparedPolygon;
use crate::graph::extend::prune_and_extend;
use crate::graph::prune::PruneParams;
use crate::graph::widths::medial_axis_transform;
use crate::graph::SkeletonGraph;
use crate::methods::budget::{self, MethodContext};
use crate::numbers::sig;
use crate::score::{metrics, BarRays};
use geo::{LineString, MultiLineString};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// Every method's candidate for the polygon parts `prepared`, in `methods`
/// order.
pub(super) fn computed(
    prepared: &[PreparedPolygon],
    params: &ProcessParams,
) -> Vec<super::Candidate> {
    let n = prepared.len();
    let parallel = worth_splitting(prepared);
    // Worked on one thread: stages on the wall clock, scaled to this
    // thread's CPU time over the feature at the end (two CPU clock readings
    // per feature instead of dozens).
    let whole = (!parallel).then(|| (CpuClock::start(), std::time::Instant::now()));
    let skeletons = || -> Vec<Vec<(Result<PartSkeleton, CandidateError>, StageTimes)>> {
        prepared
            .iter()
            .enumerate()
            .map(|(i, p)| {
                part_skeletons(p, params, parallel)
                    .into_iter()
                    .map(|(r, t)| (r.map_err(|e| e.of_part(i, n)), t))
                    .collect()
            })
            .collect()
    };
    // The bars' rays depend on the polygon alone: found while the methods
    // work (on one huge polygon they fill a core the methods leave idle).
    let (per_part, (rays, rays_time)) = if parallel {
        let done = AtomicBool::new(false);
        rayon::join(
            || {
                let s = skeletons();
                done.store(true, Ordering::Relaxed);
                s
            },
            || bar_rays(prepared, params, Some(&done)),
        )
    } else {
        (skeletons(), bar_rays(prepared, params, None))
    };
    // The shared rays, split evenly between the methods.
    let rays_share = rays_time / params.skeleton.methods.len().max(1) as u32;
    let mut candidates = map_in_order(&params.skeleton.methods, parallel, |k, &m| {
        let mut time = StageTimes::default();
        for (_, t) in per_part.iter().map(|r| &r[k]) {
            time += *t;
        }
        let parts: Result<Vec<PartSkeleton>, CandidateError> = per_part
            .iter()
            .map(|r| r[k].0.clone())
            .collect::<Result<_, _>>()
            .and_then(|parts| every_part_has_a_skeleton(parts, m, prepared));
        let result = parts.and_then(|parts| {
            scoring_budget(m, &parts, &rays, params)?;
            let (c, t) = finish(prepared, &rays, &parts, params, parallel);
            time.score += t + rays_share;
            scoring_budget(m, &parts, &[], params)?;
            Ok(c)
        });
        super::Candidate {
            method: m,
            result,
            time,
        }
    });
    if let Some((cpu, wall)) = whole {
        let k = Stopwatch::scale(cpu.elapsed(), wall.elapsed());
        for c in &mut candidates {
            c.time.skeleton = c.time.skeleton.mul_f64(k);
            c.time.prune_extend = c.time.prune_extend.mul_f64(k);
            c.time.score = c.time.score.mul_f64(k);
        }
    }
    candidates
}

/// The skeletons of a multipolygon's parts, or the error naming a part
/// that `m` has no skeleton of while it has one of others: a candidate
/// that lost a polygon part is no candidate of the feature (alone, the
/// part would be rejected with the reason). The reason gives the part's
/// area and the two ways out: skipping parts that small, or a method that
/// gives one (a one-pixel piece of a vectorised water mask has no Voronoi
/// skeleton, and with VD alone it would cost the whole river).
fn every_part_has_a_skeleton(
    parts: Vec<PartSkeleton>,
    m: crate::methods::MethodId,
    prepared: &[PreparedPolygon],
) -> Result<Vec<PartSkeleton>, CandidateError> {
    let n = parts.len();
    let empty = parts.iter().position(|p| p.graph.is_empty());
    match empty {
        Some(i) if parts.iter().any(|p| !p.graph.is_empty()) => {
            let area = |p: &PreparedPolygon| geo::Area::unsigned_area(p.polygon());
            let part = prepared.get(i).map_or(f64::NAN, area);
            let whole: f64 = prepared.iter().map(area).sum();
            Err(CandidateError::LostPart {
                method: m,
                area: sig(part, 4),
                whole: sig(whole, 4),
                min_area: sig(part * 1.01, 4),
                other: if m == crate::methods::MethodId::MA {
                    crate::methods::MethodId::CDT
                } else {
                    crate::methods::MethodId::MA
                },
            }
            .of_part(i, n))
        }
        _ => Ok(parts),
    }
}

/// A feature of at most this many boundary vertices is worked on one
/// thread: its methods take well under a millisecond each, less than
/// handing them to other threads costs, and a layer of many such features
/// keeps every core busy feature by feature. Its bars are never split
/// either (at most three per vertex).
const SEQUENTIAL_VERTICES: usize = 1000;
const _: () = assert!(3 * SEQUENTIAL_VERTICES <= crate::score::PAR_BARS);

/// True when the feature's work is split between threads.
fn worth_splitting(prepared: &[PreparedPolygon]) -> bool {
    prepared
        .iter()
        .map(PreparedPolygon::vertex_count)
        .sum::<usize>()
        > SEQUENTIAL_VERTICES
}

/// A given skeleton (lines made by another tool) as a candidate: the same
/// lines scored against every polygon part.
pub(super) fn given(
    prepared: &[PreparedPolygon],
    lines: &MultiLineString<f64>,
    params: &ProcessParams,
) -> CandidateSkeleton {
    let graph = SkeletonGraph::from_lines(lines);
    let legs = graph.leg_count();
    let parts: Vec<PartSkeleton> = prepared
        .iter()
        .map(|_| PartSkeleton {
            graph: graph.clone(),
            legs_raw: legs,
            ctx: MethodContext::default(),
            raw: None,
            cells: None,
        })
        .collect();
    let parallel = worth_splitting(prepared);
    // Nothing is made beside the rays here: every core on them at once.
    let nothing_beside = AtomicBool::new(true);
    let rays = bar_rays(prepared, params, parallel.then_some(&nothing_beside)).0;
    let (mut c, _) = finish(prepared, &rays, &parts, params, parallel);
    // The lines once, not once per polygon part.
    c.geometry = lines.clone();
    c.components = graph.components();
    c.legs = legs;
    c.legs_raw = legs;
    c
}

/// One method's finished skeleton of one polygon part.
#[derive(Debug, Clone)]
pub(super) struct PartSkeleton {
    graph: crate::graph::SkeletonGraph,
    legs_raw: usize,
    /// The method's budget on this part (its clock started with the raw
    /// skeleton); scoring is under it too.
    ctx: MethodContext,
    /// The raw skeleton, when kept for a registered step (MA's, see
    /// [`ProcessParams::keeps_raw_medial_axis`]).
    raw: Option<std::sync::Arc<SkeletonGraph>>,
    /// The cells of MA's diagram, when a step needs them (see
    /// [`crate::methods::SkeletonMethod::skeletonise_with_cells`]).
    cells: Option<Cells>,
}

/// The cells of a polygon part's segment Voronoi diagram inside it.
type Cells = std::sync::Arc<crate::methods::medial_axis::cells::DiagramCells>;

/// Every method's finished skeleton of one polygon part, in `methods`
/// order, as the SPEC sequences them: the raw skeletons, then the
/// reference's pruned and extended skeleton (the structure every method
/// shares), then the others conformed to it (or each finished on its own).
/// With each result, the time its skeleton and its pruning took.
pub(super) fn part_skeletons(
    p: &PreparedPolygon,
    params: &ProcessParams,
    parallel: bool,
) -> Vec<(Result<PartSkeleton, CandidateError>, StageTimes)> {
    let work = PartWork::new(p, params, parallel);
    if let Some(why) = work.dropped() {
        return params
            .skeleton
            .methods
            .iter()
            .map(|_| (Err(why.clone()), StageTimes::default()))
            .collect();
    }
    // A reference that is no candidate (`skeleton.reference` not among
    // `methods`) is made beside the candidates' raw skeletons.
    let (mut raws, hidden) = if parallel && work.hidden.is_some() {
        rayon::join(|| work.raw_skeletons(), || work.hidden_reference())
    } else {
        (work.raw_skeletons(), work.hidden_reference())
    };
    let reference = match hidden {
        Some((r, time)) => {
            // Its time is the candidates' pruning, shared evenly.
            let share = time / raws.len().max(1) as u32;
            for raw in &mut raws {
                raw.stages.add(Stage::Prune, share);
            }
            r.or_else(|| work.reference(&mut raws))
        }
        None => work.reference(&mut raws),
    };
    work.conformed(raws, reference.as_ref())
}

/// The reference's index among the methods ([`HIDDEN`] for a reference
/// that is no candidate), its structure and its finished skeleton.
type Reference = (usize, crate::graph::structure::Structure, SkeletonGraph);

/// The index of a reference that is not among the methods.
const HIDDEN: usize = usize::MAX;

/// One method's raw skeleton of a polygon part, the time taken so far, and
/// (for the first method of the reference order) its finished skeleton.
struct Raw {
    graph: Result<SkeletonGraph, CandidateError>,
    /// The cells of MA's diagram, when a step needs them.
    cells: Option<Cells>,
    stages: Stages,
    reference: Option<Reference>,
    /// Whether its finished skeleton was tried as the reference.
    tried: bool,
    /// The method's budget on this part, its clock started with the raw
    /// skeleton: pruning, extension and scores are under it too.
    ctx: MethodContext,
}

/// The work on one polygon part: the polygon, the steps, whether its work
/// is split between threads, and the methods in the order they are tried as
/// the reference (empty when the structure is not shared).
struct PartWork<'a> {
    p: &'a PreparedPolygon,
    params: &'a ProcessParams,
    parallel: bool,
    order: Vec<usize>,
    /// The reference method when it is not among the methods: its
    /// structure is made for the others all the same (on a rough boundary
    /// a lone CDT, VD, DVD or StSk pruned on its own keeps thousands of
    /// legs; against the medial axis' structure it keeps the few it has).
    hidden: Option<crate::methods::MethodId>,
    trunk: bool,
    /// The pruning this part gets: the step's, or with `mode: network` and
    /// no connection point the fallback's (`None`: no pruning, or dropped).
    prune: Option<PruneParams>,
    /// With `mode: network`: the part's connection points (empty: the
    /// fallback applies).
    network: Option<Vec<geo::Coord<f64>>>,
}

impl<'a> PartWork<'a> {
    fn new(p: &'a PreparedPolygon, params: &'a ProcessParams, parallel: bool) -> Self {
        use crate::graph::prune::{PruneMode, Structure as Sharing};
        let methods = &params.skeleton.methods;
        let network = params
            .prune
            .filter(|pr| pr.mode == PruneMode::Network)
            .map(|_| {
                let mut points: Vec<geo::Coord<f64>> = params
                    .connect
                    .as_ref()
                    .map(|net| net.points(p).into_iter().map(|(_, c)| c).collect())
                    .unwrap_or_default();
                points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
                points.dedup();
                points
            });
        let connected = network.as_ref().is_some_and(|n| !n.is_empty());
        let prune = match params.prune {
            Some(pr) if pr.mode == PruneMode::Network && !connected => pr.without_connections(),
            other => other,
        };
        // The reference alone has no other to share its structure with: it
        // is finished on its own (the same skeleton as its reference path).
        let reference = params.skeleton.reference;
        let shared = prune
            .filter(|pr| pr.mode != PruneMode::None && pr.structure == Sharing::Shared)
            .filter(|_| methods.len() > 1 || methods.first() != Some(&reference));
        let hidden = shared
            .filter(|_| !methods.contains(&reference))
            .map(|_| reference);
        let order = shared.map_or_else(Vec::new, |_| {
            params
                .skeleton
                .reference_order()
                .into_iter()
                .filter_map(|m| methods.iter().position(|&x| x == m))
                .collect()
        });
        Self {
            p,
            params,
            parallel,
            order,
            hidden,
            trunk: prune.is_some_and(|pr| pr.mode == PruneMode::Trunk),
            prune,
            network: network.filter(|_| connected),
        }
    }

    /// Why this part gets no skeleton: `mode: network`, no line meets it,
    /// and `fallback: drop`.
    fn dropped(&self) -> Option<CandidateError> {
        let asked = self.params.prune?;
        (asked.mode == crate::graph::prune::PruneMode::Network
            && self.network.is_none()
            && self.prune.is_none())
        .then_some(CandidateError::NoConnection)
    }

    /// A raw skeleton pruned and extended on its own (with `mode: network`,
    /// its through-lines between the connection points; `None` when
    /// `expired()` stopped their search).
    fn finish(&self, raw: &SkeletonGraph, expired: &dyn Fn() -> bool) -> Option<SkeletonGraph> {
        if let Some(points) = &self.network {
            return crate::connect::through_lines(raw, self.p, points, expired);
        }
        Some(self.junctions(prune_and_extend(
            raw,
            self.p,
            self.prune.as_ref(),
            self.params.extend.as_ref(),
        )))
    }

    /// `g` with its junctions merged where `prune.junctions` asks it, and
    /// its roundabouts made one node where `prune.roundabouts` gives their
    /// size.
    fn junctions(&self, g: SkeletonGraph) -> SkeletonGraph {
        use crate::graph::junctions::{merge, Junctions};
        let Some(prune) = self.params.prune else {
            return g;
        };
        let g = match prune.junctions {
            Junctions::Merge => merge(&g, self.p),
            Junctions::Keep => g,
        };
        match prune.roundabouts > 0.0 {
            true => crate::graph::roundabouts::roundabouts(&g, self.p, prune.roundabouts),
            false => g,
        }
    }

    /// Another method's raw skeleton conformed to the reference's structure
    /// (with `mode: network`, then reduced to its through-lines as the
    /// reference was: a conformed end that could not be joined to its
    /// connection point gets a leg to it, and what no path between two
    /// connection points uses goes).
    fn conform(
        &self,
        raw: &SkeletonGraph,
        s: &crate::graph::structure::Structure,
        expired: &dyn Fn() -> bool,
    ) -> Option<SkeletonGraph> {
        let g = crate::graph::structure::conform(raw, s, self.p);
        match &self.network {
            Some(points) => crate::connect::through_lines(&g, self.p, points, expired),
            None => Some(self.junctions(g)),
        }
    }

    /// Method `k`'s finished skeleton as the reference, when not empty (a
    /// polygon thinner than MA's grid has no medial axis).
    /// Fails (method `k`'s error on this part) when its pruning and
    /// extension would need more memory than the budget allows, or ran past
    /// its deadline.
    fn reference_of(
        &self,
        k: usize,
        raw: &SkeletonGraph,
        ctx: &MethodContext,
    ) -> Result<Option<Reference>, CandidateError> {
        let m = self.params.skeleton.methods[k];
        let g = self.staged(m, ctx, |x| self.finish(raw, x))?;
        Ok((!g.is_empty()).then(|| {
            (
                k,
                crate::graph::structure::Structure::of(&g, self.p, self.trunk),
                g,
            )
        }))
    }

    /// `finish` (pruning and extending, method `m`) under the method's
    /// budget: declined when its working memory would pass
    /// `skeleton.max_memory_mb`, dropped when it ended past the deadline
    /// (judged when it returns; a search whose cost can grow faster than
    /// the polygon — network pruning's — asks the deadline as it goes, via
    /// the `expired` it is given, and stops).
    fn staged(
        &self,
        m: crate::methods::MethodId,
        ctx: &MethodContext,
        finish: impl FnOnce(&dyn Fn() -> bool) -> Option<SkeletonGraph>,
    ) -> Result<SkeletonGraph, CandidateError> {
        const STAGE: &str = "pruning and extending";
        let bytes = PRUNE_BYTES_PER_VERTEX * self.p.vertex_count() as f64;
        ctx.check_stage(m, STAGE)
            .and_then(|()| ctx.afford_stage(m, STAGE, bytes))?;
        let expired = || ctx.check_stage(m, STAGE).is_err();
        let g = finish(&expired);
        ctx.check_stage(m, STAGE)?;
        g.ok_or(CandidateError::PruningStopped)
    }

    /// Every method's raw skeleton. The first of the reference order is
    /// finished in its own task as soon as its raw skeleton is there, while
    /// the other methods' are still being made (on one huge polygon this
    /// keeps both cores busy).
    fn raw_skeletons(&self) -> Vec<Raw> {
        let methods = &self.params.skeleton.methods;
        let raw = |k: usize| {
            let m = methods[k];
            let ctx = MethodContext::start(self.params.skeleton.budget());
            let mut stages = Stages::new(self.parallel);
            let with_cells = m == crate::methods::MethodId::MA && self.params.needs().cells;
            let made = stages.time(Stage::Skeleton, || {
                self.params
                    .registry
                    .build(m, &self.params.skeleton)
                    .ok_or(CandidateError::NotRegistered(m))
                    .and_then(|method| {
                        guarded(m, || {
                            Ok(budget::within(m, &ctx, |ctx| match with_cells {
                                true => method.skeletonise_with_cells(self.p, ctx),
                                false => method.skeletonise(self.p, ctx).map(|g| (g, None)),
                            })?)
                        })
                    })
            });
            let (mut graph, cells) = match made {
                Ok((g, cells)) => (Ok(g), cells.map(std::sync::Arc::new)),
                Err(e) => (Err(e), None),
            };
            // The cells are the work of the step that needs them: its time,
            // not the skeleton's.
            if let Some(c) = &cells {
                stages.remove(Stage::Skeleton, c.time);
            }
            let mut reference = None;
            let tried = self.hidden.is_none() && self.order.first() == Some(&k);
            if tried {
                if let Ok(g) = &graph {
                    match stages.time(Stage::Prune, || self.reference_of(k, g, &ctx)) {
                        Ok(r) => reference = r,
                        Err(e) => graph = Err(e),
                    }
                }
            }
            Raw {
                graph,
                cells,
                stages,
                reference,
                tried,
                ctx,
            }
        };
        if !self.parallel {
            return (0..methods.len()).map(raw).collect();
        }
        // Started in the order of their usual cost, the longest first, each
        // by the next free thread: split in halves by index, a staircase's
        // straight skeleton started after the medial axis and its pruning
        // and ran on alone while the other core had nothing left to do.
        let mut start: Vec<usize> = (0..methods.len()).collect();
        start.sort_by_key(|&k| usual_cost_rank(methods[k]));
        let slots: Vec<std::sync::Mutex<Option<Raw>>> = methods
            .iter()
            .map(|_| std::sync::Mutex::new(None))
            .collect();
        rayon::scope_fifo(|s| {
            for &k in &start {
                let (raw, slot) = (&raw, &slots[k]);
                s.spawn_fifo(move |_| {
                    let r = raw(k);
                    *slot.lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
                });
            }
        });
        slots
            .into_iter()
            .map(|slot| {
                slot.into_inner()
                    .unwrap_or_else(|e| e.into_inner())
                    .expect("every method's task ran")
            })
            .collect()
    }

    /// The reference's finished skeleton when it is no candidate (`None`
    /// inside when it has none: a polygon thinner than its grid, or over
    /// its budget; the candidates are then tried in the reference order),
    /// and the time it took.
    fn hidden_reference(&self) -> Option<(Option<Reference>, std::time::Duration)> {
        let m = self.hidden?;
        let mut stages = Stages::new(self.parallel);
        let r = stages.time(Stage::Prune, || {
            let ctx = MethodContext::start(self.params.skeleton.budget());
            let method = self.params.registry.build(m, &self.params.skeleton)?;
            let raw = guarded(m, || {
                Ok(budget::within(m, &ctx, |ctx| {
                    method.skeletonise(self.p, ctx)
                })?)
            })
            .ok()?;
            let g = self.staged(m, &ctx, |x| self.finish(&raw, x)).ok()?;
            (!g.is_empty()).then(|| {
                (
                    HIDDEN,
                    crate::graph::structure::Structure::of(&g, self.p, self.trunk),
                    g,
                )
            })
        });
        Some((r, stages.times().prune_extend))
    }

    /// The reference: the first method in the reference order whose
    /// finished skeleton is not empty (the first one's was finished with
    /// its raw skeleton; the others are tried in turn, their time theirs).
    fn reference(&self, raws: &mut [Raw]) -> Option<Reference> {
        if let Some(r) = raws.iter_mut().find_map(|r| r.reference.take()) {
            return Some(r);
        }
        for &k in &self.order {
            if raws[k].tried {
                continue;
            }
            let Ok(raw) = &raws[k].graph else { continue };
            let mut stages = Stages::new(self.parallel);
            let r = stages.time(Stage::Prune, || self.reference_of(k, raw, &raws[k].ctx));
            raws[k]
                .stages
                .add(Stage::Prune, stages.times().prune_extend);
            match r {
                Ok(Some(r)) => return Some(r),
                Ok(None) => {}
                Err(e) => raws[k].graph = Err(e),
            }
        }
        None
    }

    /// Every method's finished skeleton: the reference's own, the others
    /// conformed to its structure (or, with no structure to share, each
    /// pruned and extended on its own).
    fn conformed(
        &self,
        raws: Vec<Raw>,
        reference: Option<&Reference>,
    ) -> Vec<(Result<PartSkeleton, CandidateError>, StageTimes)> {
        let methods = &self.params.skeleton.methods;
        let keep_ma = self.params.keeps_raw_medial_axis();
        map_in_order(&raws, self.parallel, |k, raw| {
            let mut stages = raw.stages;
            let result = stages.time(Stage::Prune, || {
                let g = raw.graph.as_ref().map_err(Clone::clone)?;
                let finished = guarded(methods[k], || match reference {
                    Some((r, _, g)) if *r == k => Ok(g.clone()),
                    Some((_, s, _)) => self.staged(methods[k], &raw.ctx, |x| self.conform(g, s, x)),
                    None => self.staged(methods[k], &raw.ctx, |x| self.finish(g, x)),
                })?;
                let kept = keep_ma && methods[k] == crate::methods::MethodId::MA;
                Ok(PartSkeleton {
                    graph: finished,
                    legs_raw: g.leg_count(),
                    ctx: raw.ctx,
                    raw: kept.then(|| std::sync::Arc::new(g.clone())),
                    cells: raw.cells.clone(),
                })
            });
            (result, stages.times())
        })
    }
}

/// Where a method's raw skeleton is started among the others on a large
/// polygon: the usually longest first (the doubling benchmark's order on
/// rough polygons: StSk, DVD, MA, VD, CDT; a registered method last).
fn usual_cost_rank(m: crate::methods::MethodId) -> u8 {
    use crate::methods::MethodId;
    match m {
        MethodId::STSK => 0,
        MethodId::DVD => 1,
        MethodId::MA => 2,
        MethodId::VD => 3,
        MethodId::CDT => 4,
        _ => 5,
    }
}

/// Runs one method's work on one polygon; a panic (a bug, which must never
/// end the run) becomes that method's error for this feature.
fn guarded<T>(
    m: crate::methods::MethodId,
    f: impl FnOnce() -> Result<T, CandidateError>,
) -> Result<T, CandidateError> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|e| {
        let what = e
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| e.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        Err(CandidateError::Internal { method: m, what })
    })
}

/// Every part's bars when the run scores (shared by all candidates), and
/// the time they took over all threads (on the feature's [`Stopwatch`]).
/// With `beside`, the feature's work is split between threads and the
/// rays are found beside its skeletons until that flag is set
/// ([`BarRays::timed_beside`]); without, on the calling thread.
fn bar_rays(
    prepared: &[PreparedPolygon],
    params: &ProcessParams,
    beside: Option<&AtomicBool>,
) -> (Vec<BarRays>, Duration) {
    if params.score.is_none() {
        return (Vec::new(), Duration::ZERO);
    }
    let parallel = beside.is_some();
    let timed = map_in_order(prepared, parallel, |_, p| {
        let clock = Stopwatch::start(parallel);
        let (rays, time) = match beside {
            Some(done) => BarRays::timed_beside(p, done),
            None => BarRays::timed(p),
        };
        (rays, time.unwrap_or_else(|| clock.elapsed()))
    });
    let time = timed.iter().map(|(_, t)| *t).sum();
    (timed.into_iter().map(|(r, _)| r).collect(), time)
}

/// One candidate from its finished skeleton of every polygon part: scored
/// (branches numbered across the parts), with bars and widths when asked
/// for.
fn finish(
    prepared: &[PreparedPolygon],
    rays: &[BarRays],
    parts: &[PartSkeleton],
    params: &ProcessParams,
    parallel: bool,
) -> (CandidateSkeleton, Duration) {
    // CPU time: the bars' own (over every thread that cast them), plus this
    // thread's outside the casts (inside, it may run other work).
    let clock = Stopwatch::start(parallel);
    let mut cast_time = Duration::ZERO;
    let mut in_casts = Duration::ZERO;
    let mut lines = Vec::new();
    let mut all_bars = Vec::new();
    let mut widths = Vec::new();
    let mut graphs = Vec::new();
    let keep_graphs = params.needs().graphs;
    let (mut components, mut legs_raw, mut legs, mut hooks) = (0, 0, 0, 0);
    let mut branch_offset = 0;
    for (k, (p, part)) in prepared.iter().zip(parts).enumerate() {
        let g: &SkeletonGraph = &part.graph;
        legs_raw += part.legs_raw;
        let branches = g.branches();
        legs += g.leg_count_in(&branches);
        components += g.components();
        if params.score.is_some() {
            // Cast in parallel, this thread may run other work meanwhile: the
            // casts' own CPU time replaces this thread's; cast here, its
            // clock counts them.
            let here = rays[k].parallel().then(CpuClock::start);
            let (mut b, t, parts) = rays[k].cast_on_branches(p, &branches);
            if let (Some(here), Some(t)) = (here, t) {
                in_casts += here.elapsed();
                cast_time += t;
            }
            for bar in &mut b {
                if let Some(h) = &mut bar.hit {
                    h.part += branch_offset;
                }
            }
            branch_offset += parts;
            all_bars.extend(b);
            hooks += crate::score::defects::end_turns(g, p)
                .iter()
                .filter(|&&t| t > crate::score::defects::HOOK_DEG)
                .count();
        }
        if params.keep_widths {
            widths.extend(medial_axis_transform(g, Some(p.boundary())));
        }
        if keep_graphs {
            graphs.push(g.clone());
        }
        // The branches as lines (`SkeletonGraph::to_multilinestring`).
        lines.extend(branches.into_iter().map(|b| LineString(b.coords)));
    }
    let scores = params.score.map(|_| metrics(&all_bars));
    if !params.keep_bars {
        all_bars.clear();
    }
    let c = CandidateSkeleton {
        geometry: MultiLineString(lines),
        scores,
        components,
        legs_raw,
        legs,
        hooks,
        bars: all_bars,
        widths,
        graphs,
        raw: parts.iter().filter_map(|p| p.raw.clone()).collect(),
        cells: parts.iter().filter_map(|p| p.cells.clone()).collect(),
        note: None,
    };
    (c, cast_time + clock.elapsed().saturating_sub(in_casts))
}

/// A method's working memory in pruning and extension per boundary vertex
/// of the polygon: the peak measured with `examples/stage_memory.rs` is
/// 450–590 bytes for MA (Lena reaches, the rough 200 000-vertex polygon)
/// and 280 for CDT; with room for the allocator. (Per raw-skeleton node it
/// varies fourfold between MA's grid and the others.)
const PRUNE_BYTES_PER_VERTEX: f64 = 1000.0;

/// Scoring `parts` (method `m`) under its budget: declined when the bars
/// it casts (`rays`, one bar each, when the run scores) would pass
/// `skeleton.max_memory_mb`, failed when a part's deadline has passed
/// (checked before scoring and after it, with no rays).
fn scoring_budget(
    m: crate::methods::MethodId,
    parts: &[PartSkeleton],
    rays: &[BarRays],
    params: &ProcessParams,
) -> Result<(), CandidateError> {
    const STAGE: &str = "scoring";
    if params.score.is_none() {
        return Ok(());
    }
    let bars: usize = rays.iter().map(BarRays::len).sum();
    let bytes = (bars * std::mem::size_of::<crate::score::Bar>()) as f64;
    parts
        .iter()
        .try_for_each(|p| {
            p.ctx
                .check_stage(m, STAGE)
                .and_then(|()| p.ctx.afford_stage(m, STAGE, bytes))
        })
        .map_err(CandidateError::from)
}

/// `f` over `items`, results in the items' order: in parallel, or on the
/// calling thread when `parallel` is false (work too small to be worth
/// splitting, or a caller that keeps to one thread). The same results
/// either way.
pub fn map_in_order<T: Sync, U: Send>(
    items: &[T],
    parallel: bool,
    f: impl Fn(usize, &T) -> U + Sync + Send,
) -> Vec<U> {
    use rayon::prelude::*;
    if parallel {
        items.par_iter().enumerate().map(|(i, t)| f(i, t)).collect()
    } else {
        items.iter().enumerate().map(|(i, t)| f(i, t)).collect()
    }
}
