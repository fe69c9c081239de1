//! The indexed binary min-heap of collapse candidates.

use super::*;

/// A heap key: (priority, squared edge length, vertex), compared lexicographically.
pub(super) type Key = (u64, u64, u32);

/// Binary min-heap of vertices with updatable keys (each vertex at most once). Each entry
/// carries its key, so sifting compares contiguous memory instead of looking keys up by
/// vertex.
pub(super) struct IndexedHeap {
    pub(super) items: Vec<(Key, u32)>,
    /// Position of each vertex in `items`, or `NONE`.
    pub(super) at: Vec<u32>,
}

impl IndexedHeap {
    pub(super) fn new(n: usize) -> Self {
        Self {
            items: Vec::with_capacity(n),
            at: vec![NONE; n],
        }
    }

    pub(super) fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    pub(super) fn clear(&mut self) {
        for &(_, v) in &self.items {
            self.at[v as usize] = NONE;
        }
        self.items.clear();
    }

    /// Inserts `v` or changes its key.
    pub(super) fn set(&mut self, v: u32, k: Key) {
        let vi = v as usize;
        let i = self.at[vi];
        if i == NONE {
            self.items.push((k, v));
            self.at[vi] = (self.items.len() - 1) as u32;
            self.up(self.items.len() - 1);
        } else {
            let i = i as usize;
            self.items[i].0 = k;
            self.up(i);
            self.down(self.at[vi] as usize);
        }
    }

    pub(super) fn remove(&mut self, v: u32) {
        let i = self.at[v as usize];
        if i == NONE {
            return;
        }
        let i = i as usize;
        let last = self.items.pop().expect("non-empty");
        self.at[v as usize] = NONE;
        if i < self.items.len() {
            self.items[i] = last;
            self.at[last.1 as usize] = i as u32;
            self.up(i);
            self.down(self.at[last.1 as usize] as usize);
        }
    }

    pub(super) fn pop(&mut self) -> Option<u32> {
        let v = self.items.first()?.1;
        self.remove(v);
        Some(v)
    }

    #[inline]
    pub(super) fn less(&self, a: usize, b: usize) -> bool {
        self.items[a].0 < self.items[b].0
    }

    pub(super) fn swap(&mut self, a: usize, b: usize) {
        self.items.swap(a, b);
        self.at[self.items[a].1 as usize] = a as u32;
        self.at[self.items[b].1 as usize] = b as u32;
    }

    pub(super) fn up(&mut self, mut i: usize) {
        while i > 0 {
            let p = (i - 1) / 2;
            if !self.less(i, p) {
                break;
            }
            self.swap(i, p);
            i = p;
        }
    }

    pub(super) fn down(&mut self, mut i: usize) {
        loop {
            let (l, r) = (2 * i + 1, 2 * i + 2);
            let mut m = i;
            if l < self.items.len() && self.less(l, m) {
                m = l;
            }
            if r < self.items.len() && self.less(r, m) {
                m = r;
            }
            if m == i {
                break;
            }
            self.swap(i, m);
            i = m;
        }
    }
}
