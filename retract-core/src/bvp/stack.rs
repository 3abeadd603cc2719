//! A stack of vectors of one element type, kept with their capacity: what the solver's
//! workspace is made of. Imports nothing of the planner.

/// Vectors of one element type, each handed out empty with at least the capacity asked for
/// and given back when its contents are no longer needed.
pub(super) struct Stack<T>(Vec<Vec<T>>);

impl<T> Default for Stack<T> {
    fn default() -> Self {
        Self(Vec::new())
    }
}

impl<T> Stack<T> {
    /// An empty vector with capacity at least `len`: the smallest kept one that holds it, else
    /// the largest kept one grown (a new one if none is kept).
    pub fn take(&mut self, len: usize) -> Vec<T> {
        let fits = (self.0.iter().enumerate())
            .filter(|(_, v)| v.capacity() >= len)
            .min_by_key(|(_, v)| v.capacity());
        let pick = fits
            .or_else(|| self.0.iter().enumerate().max_by_key(|(_, v)| v.capacity()))
            .map(|(i, _)| i);
        let mut v = pick.map_or_else(Vec::new, |i| self.0.swap_remove(i));
        v.clear();
        v.reserve(len);
        v
    }

    /// Keeps `v` (emptied) for a later [`Self::take`] (unless it has no capacity).
    pub fn give(&mut self, mut v: Vec<T>) {
        if v.capacity() > 0 {
            v.clear();
            self.0.push(v);
        }
    }
}

impl<T> Stack<T> {
    /// The number of vectors kept.
    pub fn len(&self) -> usize {
        self.0.len()
    }
}
