// SPDX-License-Identifier:BSL-1.0

//! The ordered container under the beach line: what C++ Boost.Polygon keeps
//! in a `std::map` with an insertion hint, here a treap whose nodes live in
//! one vector, threaded by a doubly linked list in key order.
//!
//! It replaces `cpp_map::SkipList` (boostvoronoi 0.12.1) with the same
//! operations and the same answers — the same positions for the same
//! comparisons, node slots handed out in the same order (a freed slot is
//! reused first-in, first-out), duplicates refused in the same way — but:
//! - an insertion next to a known node (a hint, or the position a search
//!   found) links the new node in place and rotates it up by its priority,
//!   expected O(1) work, where the skip list walked down from its head
//!   comparing ranks (O(log n) cache misses per insertion on a beach line of
//!   a million arcs);
//! - a removal rotates the node down to a leaf (expected O(1)) instead of a
//!   second walk from the head;
//! - values are stored in the node (no reference-counted cell per node),
//!   and nothing allocates but the node vector and the free list.
//!
//! Searches compare only `node < key` with the key searched for, as the
//! skip list did: the beach line's comparison is meaningful only between a
//! new key and the nodes already in the line.

use std::collections::VecDeque;
use std::fmt;

/// Strict "less than" of the beach line's keys.
pub(crate) trait IsLessThan {
    /// `self < other`.
    fn is_less_than(&self, other: &Self) -> bool;
}

/// Neither key is less than the other.
#[inline(always)]
fn is_equal<K: IsLessThan>(a: &K, b: &K) -> bool {
    !a.is_less_than(b) && !b.is_less_than(a)
}

/// A node's slot: stable for as long as the node is in the list.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Debug)]
pub struct Index(pub(crate) usize);

impl fmt::Display for Index {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// No node.
const NIL: u32 = u32::MAX;

#[derive(Clone, Debug)]
struct Node<K, V> {
    /// `None` in a free slot.
    kv: Option<(K, V)>,
    /// Neighbours in key order.
    prev: u32,
    next: u32,
    /// The treap.
    left: u32,
    right: u32,
    parent: u32,
    priority: u32,
}

/// An ordered list of unique keys with stable slots (see the module doc).
#[derive(Clone, Debug)]
pub(crate) struct OrderedList<K, V> {
    nodes: Vec<Node<K, V>>,
    /// Freed slots, reused first-in, first-out.
    free: VecDeque<u32>,
    root: u32,
    first: u32,
    last: u32,
    len: usize,
    /// xorshift state for the priorities (fixed seed: the same input gives
    /// the same tree, so every run does the same work).
    seed: u32,
}

impl<K, V> Default for OrderedList<K, V> {
    fn default() -> Self {
        Self {
            nodes: Vec::new(),
            free: VecDeque::new(),
            root: NIL,
            first: NIL,
            last: NIL,
            len: 0,
            seed: 0x9E37_79B9,
        }
    }
}

/// Where a new node goes: after this node, or first.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum After {
    Head,
    Node(u32),
}

impl<K: IsLessThan, V> OrderedList<K, V> {
    /// Number of nodes (tests and debug output).
    #[allow(dead_code)]
    #[inline(always)]
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// True without nodes.
    #[inline(always)]
    pub(crate) fn is_empty(&self) -> bool {
        self.len == 0
    }

    #[inline(always)]
    fn some(i: u32) -> Option<Index> {
        (i != NIL).then_some(Index(i as usize))
    }

    /// The first node in key order.
    #[inline(always)]
    pub(crate) fn first(&self) -> Option<Index> {
        Self::some(self.first)
    }

    /// The last node in key order.
    #[inline(always)]
    pub(crate) fn last(&self) -> Option<Index> {
        Self::some(self.last)
    }

    /// The node after `current`.
    #[inline(always)]
    pub(crate) fn next_pos(&self, current: Option<Index>) -> Option<Index> {
        Self::some(self.nodes.get(current?.0)?.next)
    }

    /// The node before `current`.
    #[inline(always)]
    pub(crate) fn prev_pos(&self, current: Option<Index>) -> Option<Index> {
        Self::some(self.nodes.get(current?.0)?.prev)
    }

    /// True for a slot that was ever handed out (as the skip list answered).
    #[inline(always)]
    pub(crate) fn is_pos_valid(&self, index: Option<Index>) -> bool {
        index.is_some_and(|i| i.0 < self.nodes.len())
    }

    /// True at the first node, or for `None` in an empty list.
    #[inline(always)]
    pub(crate) fn is_at_first(&self, pos: Option<Index>) -> bool {
        pos == self.first()
    }

    /// True at the last node, or for `None` in an empty list.
    #[inline(always)]
    pub(crate) fn is_at_last(&self, pos: Option<Index>) -> bool {
        pos == self.last()
    }

    /// The key at `index`.
    #[inline(always)]
    pub(crate) fn get_k_at(&self, index: Index) -> Option<&K> {
        self.nodes.get(index.0)?.kv.as_ref().map(|(k, _)| k)
    }

    /// The value at `index`.
    #[inline(always)]
    pub(crate) fn get_v_at(&self, index: Index) -> Option<&V> {
        self.nodes.get(index.0)?.kv.as_ref().map(|(_, v)| v)
    }

    /// Key and value at `index`.
    #[inline(always)]
    pub(crate) fn get_at(&self, index: Index) -> Option<(&K, &V)> {
        self.nodes.get(index.0)?.kv.as_ref().map(|(k, v)| (k, v))
    }

    /// Replaces the value at `index`; false if there is no node.
    #[inline(always)]
    pub(crate) fn set_v_at(&mut self, index: Index, value: V) -> bool {
        match self.nodes.get_mut(index.0).and_then(|n| n.kv.as_mut()) {
            Some((_, v)) => {
                *v = value;
                true
            }
            None => false,
        }
    }

    /// Replaces the key at `index` in place. The caller keeps the order
    /// (the beach line's circle events change a bisector into one that sorts
    /// at the same place).
    pub(crate) fn change_key_of_node(&mut self, index: Index, new_key: K) -> Option<Index> {
        let (k, _) = self.nodes.get_mut(index.0)?.kv.as_mut()?;
        *k = new_key;
        Some(index)
    }

    #[inline(always)]
    fn key(&self, i: u32) -> &K {
        match &self.nodes[i as usize].kv {
            Some((k, _)) => k,
            None => unreachable!("a linked node holds a key"),
        }
    }

    /// The first node whose key is not less than `key` (C++ `lower_bound`).
    pub(crate) fn lower_bound(&self, key: &K) -> Option<Index> {
        let mut n = self.root;
        let mut found = NIL;
        while n != NIL {
            let node = &self.nodes[n as usize];
            if self.key(n).is_less_than(key) {
                n = node.right;
            } else {
                found = n;
                n = node.left;
            }
        }
        Self::some(found)
    }

    /// The last node whose key is less than `key`.
    fn before(&self, key: &K) -> After {
        let mut n = self.root;
        let mut found = After::Head;
        while n != NIL {
            let node = &self.nodes[n as usize];
            if self.key(n).is_less_than(key) {
                found = After::Node(n);
                n = node.right;
            } else {
                n = node.left;
            }
        }
        found
    }

    /// Inserts `key` at its place; an equal key already there is kept and
    /// its slot returned.
    pub(crate) fn insert(&mut self, key: K, value: V) -> Index {
        let at = self.before(&key);
        self.insert_after(at, key, value)
    }

    /// Inserts `key` searching from `hint` along the list (a node next to
    /// the key's place): toward the tail while nodes are less than the key,
    /// toward the head while the key is less; a key equal to the hint's
    /// goes before it (and is refused as a duplicate). Falls back to
    /// [`Self::insert`] where the skip list did.
    pub(crate) fn insert_with_hint(&mut self, key: K, value: V, hint: Index) -> Index {
        if self.is_empty() {
            return self.insert(key, value);
        }
        let Some(hint_k) = self.get_k_at(hint) else {
            return self.insert(key, value);
        };
        let h = hint.0 as u32;
        let at = if hint_k.is_less_than(&key) {
            let mut current = h;
            loop {
                let next = self.nodes[current as usize].next;
                if next == NIL || !self.key(next).is_less_than(&key) {
                    break After::Node(current);
                }
                current = next;
            }
        } else if key.is_less_than(hint_k) {
            let mut current = h;
            loop {
                let prev = self.nodes[current as usize].prev;
                if prev == NIL {
                    break After::Head;
                }
                if self.key(prev).is_less_than(&key) {
                    break After::Node(prev);
                }
                current = prev;
            }
        } else {
            match self.nodes[h as usize].prev {
                NIL => return self.insert(key, value),
                prev => After::Node(prev),
            }
        };
        match at {
            After::Head => self.insert(key, value),
            at => self.insert_after(at, key, value),
        }
    }

    /// Links a new node after `at` unless the next node's key equals `key`.
    fn insert_after(&mut self, at: After, key: K, value: V) -> Index {
        let next = match at {
            After::Head => self.first,
            After::Node(p) => self.nodes[p as usize].next,
        };
        if next != NIL && is_equal(self.key(next), &key) {
            return Index(next as usize);
        }
        let priority = self.priority();
        let node = Node {
            kv: Some((key, value)),
            prev: match at {
                After::Head => NIL,
                After::Node(p) => p,
            },
            next,
            left: NIL,
            right: NIL,
            parent: NIL,
            priority,
        };
        let x = match self.free.pop_front() {
            Some(slot) => {
                self.nodes[slot as usize] = node;
                slot
            }
            None => {
                self.nodes.push(node);
                (self.nodes.len() - 1) as u32
            }
        };
        // The list.
        match at {
            After::Head => self.first = x,
            After::Node(p) => self.nodes[p as usize].next = x,
        }
        if next == NIL {
            self.last = x;
        } else {
            self.nodes[next as usize].prev = x;
        }
        // The tree: the right child of the predecessor if it has none, else
        // the left child of the successor (which then has none: it is the
        // leftmost node of the predecessor's right subtree).
        if self.root == NIL {
            self.root = x;
        } else {
            match at {
                After::Node(p) if self.nodes[p as usize].right == NIL => {
                    self.nodes[p as usize].right = x;
                    self.nodes[x as usize].parent = p;
                }
                _ => {
                    debug_assert!(next != NIL && self.nodes[next as usize].left == NIL);
                    self.nodes[next as usize].left = x;
                    self.nodes[x as usize].parent = next;
                }
            }
            loop {
                let p = self.nodes[x as usize].parent;
                if p == NIL || self.nodes[p as usize].priority >= priority {
                    break;
                }
                self.rotate_up(x);
            }
        }
        self.len += 1;
        Index(x as usize)
    }

    /// Removes the node at `*cursor` and moves the cursor to the node before
    /// it, or else the one after it.
    pub(crate) fn remove_by_index(&mut self, cursor: &mut Option<Index>) -> Option<(K, V)> {
        let i = (*cursor)?.0;
        if self.nodes.get(i)?.kv.is_none() {
            return None;
        }
        let x = i as u32;
        let (prev, next) = (self.nodes[i].prev, self.nodes[i].next);
        *cursor = Self::some(prev).or(Self::some(next));
        // Down to a leaf, the child of higher priority rotated up.
        loop {
            let (l, r) = (self.nodes[i].left, self.nodes[i].right);
            let up = match (l, r) {
                (NIL, NIL) => break,
                (c, NIL) | (NIL, c) => c,
                (l, r) => {
                    if self.nodes[l as usize].priority >= self.nodes[r as usize].priority {
                        l
                    } else {
                        r
                    }
                }
            };
            self.rotate_up(up);
        }
        match self.nodes[i].parent {
            NIL => self.root = NIL,
            p => {
                let pn = &mut self.nodes[p as usize];
                if pn.left == x {
                    pn.left = NIL;
                } else {
                    pn.right = NIL;
                }
            }
        }
        if prev == NIL {
            self.first = next;
        } else {
            self.nodes[prev as usize].next = next;
        }
        if next == NIL {
            self.last = prev;
        } else {
            self.nodes[next as usize].prev = prev;
        }
        let node = &mut self.nodes[i];
        node.parent = NIL;
        node.prev = NIL;
        node.next = NIL;
        let kv = node.kv.take();
        self.free.push_back(x);
        self.len -= 1;
        kv
    }

    /// Removes every node.
    pub(crate) fn clear(&mut self) {
        let mut n = self.first;
        while n != NIL {
            let next = self.nodes[n as usize].next;
            self.nodes[n as usize].kv = None;
            self.free.push_back(n);
            n = next;
        }
        self.root = NIL;
        self.first = NIL;
        self.last = NIL;
        self.len = 0;
    }

    /// Key and value of every node in key order.
    pub(crate) fn iter(&self) -> impl DoubleEndedIterator<Item = (&K, &V)> + '_ {
        let mut order = Vec::with_capacity(self.len);
        let mut n = self.first;
        while n != NIL {
            order.push(n);
            n = self.nodes[n as usize].next;
        }
        order.into_iter().map(move |n| {
            let (k, v) = self.nodes[n as usize].kv.as_ref().expect("linked node");
            (k, v)
        })
    }

    fn priority(&mut self) -> u32 {
        let mut s = self.seed;
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        self.seed = s;
        s
    }

    /// Rotates `x` above its parent, keeping the in-order sequence.
    fn rotate_up(&mut self, x: u32) {
        let p = self.nodes[x as usize].parent;
        let g = self.nodes[p as usize].parent;
        if self.nodes[p as usize].left == x {
            // Right rotation: x's right subtree becomes p's left.
            let b = self.nodes[x as usize].right;
            self.nodes[p as usize].left = b;
            if b != NIL {
                self.nodes[b as usize].parent = p;
            }
            self.nodes[x as usize].right = p;
        } else {
            let b = self.nodes[x as usize].left;
            self.nodes[p as usize].right = b;
            if b != NIL {
                self.nodes[b as usize].parent = p;
            }
            self.nodes[x as usize].left = p;
        }
        self.nodes[p as usize].parent = x;
        self.nodes[x as usize].parent = g;
        if g == NIL {
            self.root = x;
        } else if self.nodes[g as usize].left == p {
            self.nodes[g as usize].left = x;
        } else {
            self.nodes[g as usize].right = x;
        }
    }

    /// Checks the structure (tests): list and tree hold the same nodes in
    /// the same order, parents match children, priorities are a heap.
    #[cfg(test)]
    pub(crate) fn validate(&self) {
        fn inorder<K, V>(l: &OrderedList<K, V>, n: u32, out: &mut Vec<u32>) {
            if n == NIL {
                return;
            }
            let node = &l.nodes[n as usize];
            for c in [node.left, node.right] {
                if c != NIL {
                    assert_eq!(l.nodes[c as usize].parent, n);
                    assert!(l.nodes[c as usize].priority <= node.priority);
                }
            }
            inorder(l, node.left, out);
            out.push(n);
            inorder(l, node.right, out);
        }
        let mut tree = Vec::new();
        inorder(self, self.root, &mut tree);
        let mut list = Vec::new();
        let mut n = self.first;
        let mut prev = NIL;
        while n != NIL {
            assert_eq!(self.nodes[n as usize].prev, prev);
            assert!(self.nodes[n as usize].kv.is_some());
            list.push(n);
            prev = n;
            n = self.nodes[n as usize].next;
        }
        assert_eq!(prev, self.last);
        assert_eq!(tree, list);
        assert_eq!(list.len(), self.len);
        if self.root != NIL {
            assert_eq!(self.nodes[self.root as usize].parent, NIL);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    impl IsLessThan for i64 {
        fn is_less_than(&self, other: &Self) -> bool {
            self < other
        }
    }

    fn keys(l: &OrderedList<i64, u32>) -> Vec<i64> {
        l.iter().map(|(k, _)| *k).collect()
    }

    /// A small deterministic generator for the tests.
    fn lcg(s: &mut u64) -> u64 {
        *s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        *s >> 33
    }

    #[test]
    fn inserts_searches_and_removals_keep_order_slots_and_shape() {
        let mut l = OrderedList::<i64, u32>::default();
        let mut model: Vec<i64> = Vec::new();
        let mut slot_of = std::collections::HashMap::new();
        let mut s = 7;
        for step in 0..20_000u32 {
            let k = (lcg(&mut s) % 3000) as i64;
            match lcg(&mut s) % 4 {
                0 | 1 => {
                    let i = l.insert(k, step);
                    match model.binary_search(&k) {
                        Ok(_) => assert_eq!(slot_of[&k], i, "a duplicate returns the node"),
                        Err(p) => {
                            model.insert(p, k);
                            let _ = slot_of.insert(k, i);
                        }
                    }
                }
                2 if !model.is_empty() => {
                    // A hint anywhere in the list finds the same place.
                    let h = model[(lcg(&mut s) as usize) % model.len()];
                    let i = l.insert_with_hint(k, step, slot_of[&h]);
                    match model.binary_search(&k) {
                        Ok(_) => assert_eq!(slot_of[&k], i),
                        Err(p) => {
                            model.insert(p, k);
                            let _ = slot_of.insert(k, i);
                        }
                    }
                }
                _ if !model.is_empty() => {
                    let p = (lcg(&mut s) as usize) % model.len();
                    let k = model.remove(p);
                    let mut cursor = Some(slot_of.remove(&k).unwrap());
                    let (rk, _) = l.remove_by_index(&mut cursor).unwrap();
                    assert_eq!(rk, k);
                    let expect = if p > 0 {
                        model.get(p - 1)
                    } else {
                        model.first()
                    };
                    assert_eq!(cursor.map(|c| *l.get_k_at(c).unwrap()), expect.copied());
                }
                _ => {}
            }
            if step % 97 == 0 {
                l.validate();
                assert_eq!(keys(&l), model);
                let probe = (lcg(&mut s) % 3100) as i64;
                let lb = l.lower_bound(&probe).map(|i| *l.get_k_at(i).unwrap());
                assert_eq!(lb, model.iter().copied().find(|&m| m >= probe));
            }
        }
        l.validate();
        assert_eq!(keys(&l), model);
        // Slots are reused first-in, first-out, as the skip list reused them.
        let before = l.nodes.len();
        let freed: Vec<u32> = l.free.iter().copied().collect();
        if let Some(&f) = freed.first() {
            let i = l.insert(1_000_000, 0);
            assert_eq!(i.0 as u32, f);
            assert_eq!(l.nodes.len(), before);
        }
    }

    #[test]
    fn a_million_ordered_hinted_inserts_stay_shallow() {
        // The beach line of a round polygon grows at one end, always next to
        // the hint: the treap must stay balanced.
        let mut l = OrderedList::<i64, u32>::default();
        let mut last = l.insert(0, 0);
        for k in 1..200_000 {
            last = l.insert_with_hint(k, 0, last);
        }
        fn depth<K, V>(l: &OrderedList<K, V>, n: u32) -> usize {
            if n == NIL {
                0
            } else {
                let node = &l.nodes[n as usize];
                1 + depth(l, node.left).max(depth(l, node.right))
            }
        }
        let d = depth(&l, l.root);
        assert!(d < 60, "depth {d} for 200 000 nodes");
        l.validate();
    }
}
