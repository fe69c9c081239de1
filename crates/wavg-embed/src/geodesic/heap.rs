//! The indexed binary heap (with decrease-key) of the vertices being marched.

use super::*;

impl Workspace {
    /// Inserts `v` into the heap or moves it up after its distance decreased.
    #[inline]
    pub(super) fn push_or_decrease(&mut self, v: u32) {
        let mut i = match self.state[v as usize] {
            FAR => {
                self.heap.push(v);
                self.heap.len() - 1
            }
            p => p as usize,
        };
        let d = self.dist[v as usize];
        while i > 0 {
            let p = (i - 1) / 2;
            let pv = self.heap[p];
            if self.dist[pv as usize] <= d {
                break;
            }
            self.heap[i] = pv;
            self.state[pv as usize] = i as u32;
            i = p;
        }
        self.heap[i] = v;
        self.state[v as usize] = i as u32;
    }

    /// Removes the vertex of smallest distance and marks it frozen.
    #[inline]
    pub(super) fn pop(&mut self) -> Option<u32> {
        let top = *self.heap.first()?;
        self.state[top as usize] = FROZEN;
        let last = self.heap.pop().expect("non-empty");
        let n = self.heap.len();
        if n > 0 {
            let d = self.dist[last as usize];
            let mut i = 0;
            loop {
                let l = 2 * i + 1;
                if l >= n {
                    break;
                }
                let r = l + 1;
                let c = if r < n
                    && self.dist[self.heap[r] as usize] < self.dist[self.heap[l] as usize]
                {
                    r
                } else {
                    l
                };
                let cv = self.heap[c];
                if self.dist[cv as usize] >= d {
                    break;
                }
                self.heap[i] = cv;
                self.state[cv as usize] = i as u32;
                i = c;
            }
            self.heap[i] = last;
            self.state[last as usize] = i as u32;
        }
        Some(top)
    }
}
