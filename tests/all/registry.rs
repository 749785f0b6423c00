//! A sixth method is one registry entry and one module: a deliberately
//! trivial `Centroid` method (a star from the polygon's centroid to every
//! vertex of its exterior) runs through the whole pipeline beside MA.

use geo::{polygon, Centroid as _, Geometry};
use skeletonise::geometry::PreparedPolygon;
use skeletonise::graph::extend::ExtendParams;
use skeletonise::graph::prune::PruneParams;
use skeletonise::graph::{GraphBuilder, SkeletonGraph};
use skeletonise::methods::{
    MethodContext, MethodEntry, MethodError, MethodId, Registry, SkeletonMethod,
};
use skeletonise::process::{process, CandidateError, ProcessParams, Processed};
use skeletonise::score::select::SelectParams;
use skeletonise::score::ScoreParams;

/// The module of the sixth method.
mod centroid {
    use super::*;

    /// Identifier of the test method.
    pub const ID: MethodId = MethodId::new("Centroid");

    /// A star from the centroid to every exterior vertex.
    pub struct Centroid;

    impl SkeletonMethod for Centroid {
        fn id(&self) -> MethodId {
            ID
        }

        fn skeletonise(
            &self,
            p: &PreparedPolygon,
            _ctx: &MethodContext,
        ) -> Result<SkeletonGraph, MethodError> {
            let c = p.polygon().centroid().ok_or(MethodError::Failed {
                method: ID,
                reason: "no centroid".into(),
            })?;
            let mut b = GraphBuilder::new();
            for v in &p.polygon().exterior().0 {
                b.segment(c.0, *v);
            }
            Ok(b.finish(p.boundary()))
        }
    }

    /// Its registry entry.
    pub const ENTRY: MethodEntry = MethodEntry {
        id: ID,
        name: "centroid star",
        description: "segments from the centroid to every exterior vertex (a test method)",
        options: &[],
        build: |_| Box::new(Centroid),
    };
}

#[test]
fn a_registered_sixth_method_runs_beside_the_built_in_ones() {
    let registry = Registry::builtin().with(centroid::ENTRY);
    assert_eq!(registry.parse("centroid"), Ok(centroid::ID));
    let mut params = ProcessParams {
        prune: Some(PruneParams::default()),
        extend: Some(ExtendParams::default()),
        score: Some(ScoreParams::default()),
        select: Some(SelectParams::default()),
        registry,
        ..ProcessParams::default()
    };
    params.skeleton.methods = vec![MethodId::MA, centroid::ID];
    let strip = Geometry::Polygon(
        polygon![(x: 0., y: 0.), (x: 40., y: 0.), (x: 40., y: 10.), (x: 0., y: 10.)],
    );
    let Processed::Done(o) = process(Some(&strip), &params) else {
        panic!("not processed");
    };
    assert_eq!(o.candidates.len(), 2);
    let c = &o.candidates[1];
    assert_eq!(c.method, centroid::ID);
    let s = c.result.as_ref().expect("the test method succeeded");
    assert!(s.scores.is_some_and(|s| s.hits > 0), "{:?}", s.scores);
    // The medial axis is centred, the star is not: MA is chosen.
    assert_eq!(o.chosen().0, &MethodId::MA);
    // Without the entry the method is an error for that candidate only.
    params.registry = Registry::builtin();
    let Processed::Done(o) = process(Some(&strip), &params) else {
        panic!("not processed");
    };
    let err = o.candidates[1].result.as_ref().unwrap_err();
    assert!(
        matches!(err, CandidateError::NotRegistered(m) if *m == centroid::ID),
        "{err}"
    );
    assert_eq!(
        err.to_string(),
        format!("method {} is not registered", centroid::ID)
    );
}

#[test]
fn the_help_lists_a_registered_method() {
    let d = skeletonise::config::describe(&Registry::builtin().with(centroid::ENTRY));
    assert!(d.contains("Centroid centroid star"), "{d}");
}
