//! The typed handles of a [`super::SkeletonGraph`]'s nodes and edges, as
//! spade keeps its handles: small indices whose number is read with
//! `index()` and made with `from_index()`, never a public field, so that a
//! handle is not mistaken for any other number.

/// Typed index of a node: `NodeId::from_index(i)` is
/// `SkeletonGraph::nodes()[i]` (of the graph that made it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId(u32);

/// Typed index of an edge: `EdgeId::from_index(i)` is
/// `SkeletonGraph::edges()[i]` (of the graph that made it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EdgeId(u32);

impl NodeId {
    /// The handle of the node at position `i` (below 2³²).
    #[inline]
    pub fn from_index(i: usize) -> Self {
        debug_assert!(u32::try_from(i).is_ok(), "node index {i}");
        Self(i as u32)
    }

    /// Its position in [`super::SkeletonGraph::nodes`].
    #[inline]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

impl EdgeId {
    /// The handle of the edge at position `i` (below 2³²).
    #[inline]
    pub fn from_index(i: usize) -> Self {
        debug_assert!(u32::try_from(i).is_ok(), "edge index {i}");
        Self(i as u32)
    }

    /// Its position in [`super::SkeletonGraph::edges`].
    #[inline]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}
