//! How much a glTF file may make the reader allocate: in proportion to its bytes.
//!
//! Accessors are checked against their buffer views and buffers before anything is
//! allocated, so a declared count can only cost what the buffer really holds. Two ways
//! remain to ask for more than the bytes hold, and both are bounded here: an accessor
//! without a buffer view (all zeros, whatever its count) and instancing (many nodes
//! placing the same mesh).

/// Elements (vertices, indices, texture coordinates) read for every byte of the file and
/// its buffers. A mesh read once costs about a quarter of an element per byte (a vertex
/// takes 12 bytes, an index 4), so a mesh may be placed by about 16 nodes before the file
/// is refused.
pub const ELEMENTS_PER_BYTE: u64 = 4;

/// Elements always allowed, whatever the file's size (small meshes placed many times).
pub const MIN_ELEMENTS: u64 = 1 << 20;

/// Nodes deeper than this below a scene's root are refused (glTF nodes form trees; a
/// deeper one is a chain written to exhaust the reader's stack).
pub const MAX_DEPTH: usize = 1024;

/// The reading budget of one file: elements left to read.
#[derive(Debug)]
pub(crate) struct Budget {
    left: u64,
    total: u64,
}

impl Budget {
    /// The budget of a file whose JSON and buffers hold `bytes` bytes.
    pub(crate) fn for_bytes(bytes: u64) -> Self {
        let total = MIN_ELEMENTS.max(bytes.saturating_mul(ELEMENTS_PER_BYTE));
        Self { left: total, total }
    }

    /// Takes `n` elements from the budget, or says why the file is refused.
    pub(crate) fn take(&mut self, n: u64, what: &str) -> Result<(), String> {
        if n > self.left {
            return Err(format!(
                "{what}: reading it would make the file's elements exceed {} \
                 ({ELEMENTS_PER_BYTE} per byte of the file and its buffers): refused",
                self.total
            ));
        }
        self.left -= n;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_budget_runs_out() {
        let mut b = Budget::for_bytes(1);
        b.take(MIN_ELEMENTS - 1, "x").unwrap();
        b.take(1, "y").unwrap();
        assert!(b.take(1, "z").unwrap_err().contains("z:"));
    }
}
