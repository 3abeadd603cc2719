//! Banded LU with partial pivoting (the unblocked algorithm of LAPACK's `dgbtf2`/`dgbtrs`).
//!
//! A has `kl` sub- and `ku` superdiagonals; row interchanges widen U to `kl + ku`
//! superdiagonals. Storage is column-major with `2 kl + ku + 1` entries per column:
//! $A_{ij}$ lives at row `kl + ku + i - j` of column `j`. Factorisation costs
//! $O(n\thinspace k_l\thinspace(k_l + k_u))$ and solves $O(n\thinspace(2k_l + k_u))$: linear in $n$.

/// A square banded matrix and, after [`BandMatrix::factor`], its LU factors.
#[derive(Clone, Debug)]
pub struct BandMatrix {
    n: usize,
    kl: usize,
    ku: usize,
    ld: usize,
    data: Vec<f64>,
    pivots: Vec<usize>,
}

impl BandMatrix {
    /// The zero matrix of size `n` with bandwidths `kl` (below) and `ku` (above).
    pub fn zeros(n: usize, kl: usize, ku: usize) -> Self {
        let ld = 2 * kl + ku + 1;
        Self {
            n,
            kl,
            ku,
            ld,
            data: vec![0.0; ld * n],
            pivots: vec![0; n],
        }
    }

    /// [`Self::zeros`], or `None` when the storage cannot be allocated (its size overflows or
    /// the allocation fails): never a panic or an allocation abort.
    pub fn try_zeros(n: usize, kl: usize, ku: usize) -> Option<Self> {
        let ld = kl.checked_mul(2)?.checked_add(ku)?.checked_add(1)?;
        let len = ld.checked_mul(n)?;
        let mut data = Vec::new();
        data.try_reserve_exact(len).ok()?;
        data.resize(len, 0.0);
        let mut pivots = Vec::new();
        pivots.try_reserve_exact(n).ok()?;
        pivots.resize(n, 0);
        Some(Self {
            n,
            kl,
            ku,
            ld,
            data,
            pivots,
        })
    }

    /// Size n.
    pub fn size(&self) -> usize {
        self.n
    }

    /// Sets every entry to zero (keeps the allocation).
    pub fn clear(&mut self) {
        self.data.iter_mut().for_each(|v| *v = 0.0);
    }

    fn at(&self, i: usize, j: usize) -> usize {
        (self.kl + self.ku + i - j) + j * self.ld
    }

    /// Whether (i, j) lies inside the band.
    pub fn in_band(&self, i: usize, j: usize) -> bool {
        i < self.n && j < self.n && i <= j + self.kl && j <= i + self.ku
    }

    /// Sets $A_{ij}$; returns `false` (and does nothing) outside the band.
    pub fn set(&mut self, i: usize, j: usize, value: f64) -> bool {
        if !self.in_band(i, j) {
            return false;
        }
        let k = self.at(i, j);
        self.data[k] = value;
        true
    }

    /// $A_{ij}$ (zero outside the band). Before factorisation only.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        if self.in_band(i, j) {
            self.data[self.at(i, j)]
        } else {
            0.0
        }
    }

    /// $y = A x$ (before factorisation).
    pub fn mul(&self, x: &[f64], y: &mut [f64]) {
        for (i, yi) in y.iter_mut().enumerate().take(self.n) {
            let lo = i.saturating_sub(self.kl);
            let hi = (i + self.ku + 1).min(self.n);
            *yi = (lo..hi).map(|j| self.get(i, j) * x[j]).sum();
        }
    }

    /// Factorises in place, $P A = L U$. Returns the first zero (or non-finite) pivot column
    /// as `Err`.
    pub fn factor(&mut self) -> Result<(), usize> {
        let (n, kl, kv, ld) = (self.n, self.kl, self.kl + self.ku, self.ld);
        let mut ju = 0;
        for j in 0..n {
            let km = kl.min(n - 1 - j);
            let col = j * ld;
            // pivot search in column j, rows j..=j+km (stored at kv..=kv+km)
            let mut jp = 0;
            let mut best = self.data[col + kv].abs();
            for p in 1..=km {
                let v = self.data[col + kv + p].abs();
                if v > best {
                    best = v;
                    jp = p;
                }
            }
            self.pivots[j] = j + jp;
            if best == 0.0 || !best.is_finite() {
                return Err(j);
            }
            ju = ju.max((j + self.ku + jp).min(n - 1));
            if jp != 0 {
                // swap rows j and j + jp over columns j..=ju
                for c in j..=ju {
                    let a = kv + j - c + c * ld;
                    let b = kv + j + jp - c + c * ld;
                    self.data.swap(a, b);
                }
            }
            let pivot = self.data[col + kv];
            for v in &mut self.data[col + kv + 1..col + kv + 1 + km] {
                *v /= pivot;
            }
            // rank-1 update of columns j+1..=ju: A(j+1..=j+km, c) -= L(j+1..=j+km) A(j, c)
            for c in j + 1..=ju {
                let cc = c * ld;
                let off = kv + j - c;
                let ajc = self.data[cc + off];
                if ajc == 0.0 {
                    continue;
                }
                let (left, right) = self.data.split_at_mut(cc);
                let l = &left[col + kv + 1..col + kv + 1 + km];
                let target = &mut right[off + 1..off + 1 + km];
                for (t, li) in target.iter_mut().zip(l) {
                    *t -= li * ajc;
                }
            }
        }
        Ok(())
    }

    /// Solves $A x = b$ in place with the factors of [`BandMatrix::factor`].
    pub fn solve(&self, b: &mut [f64]) {
        let (n, kl, kv, ld) = (self.n, self.kl, self.kl + self.ku, self.ld);
        for j in 0..n {
            let p = self.pivots[j];
            if p != j {
                b.swap(p, j);
            }
            let km = kl.min(n - 1 - j);
            let bj = b[j];
            if bj != 0.0 {
                let l = &self.data[j * ld + kv + 1..j * ld + kv + 1 + km];
                for (bi, li) in b[j + 1..j + 1 + km].iter_mut().zip(l) {
                    *bi -= li * bj;
                }
            }
        }
        for j in (0..n).rev() {
            let col = j * ld;
            b[j] /= self.data[col + kv];
            let bj = b[j];
            if bj != 0.0 {
                let top = j.saturating_sub(kv);
                // U(top..j, j) is stored at rows kv + top - j .. kv of column j
                let u = &self.data[col + kv + top - j..col + kv];
                for (bi, ui) in b[top..j].iter_mut().zip(u) {
                    *bi -= ui * bj;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic banded test matrix that needs pivoting (zero diagonal entries).
    fn sample(n: usize, kl: usize, ku: usize) -> BandMatrix {
        let mut a = BandMatrix::zeros(n, kl, ku);
        for i in 0..n {
            for j in i.saturating_sub(kl)..(i + ku + 1).min(n) {
                let v = if i == j && i % 3 == 1 {
                    0.0
                } else {
                    ((i * 7 + j * 13) % 17) as f64 / 17.0 - 0.4
                };
                a.set(i, j, v);
            }
        }
        a
    }

    #[test]
    fn solves_against_dense_product() {
        for (n, kl, ku) in [(1, 0, 0), (7, 2, 1), (40, 5, 3), (33, 1, 6), (50, 9, 9)] {
            let mut a = sample(n, kl, ku);
            let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
            let mut b = vec![0.0; n];
            a.mul(&x, &mut b);
            a.factor().unwrap();
            a.solve(&mut b);
            let err = x
                .iter()
                .zip(&b)
                .map(|(u, v)| (u - v).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-10, "n {n} kl {kl} ku {ku}: error {err:e}");
        }
    }

    #[test]
    fn reports_a_zero_pivot() {
        let mut a = BandMatrix::zeros(3, 1, 1);
        a.set(0, 0, 1.0);
        a.set(1, 1, 1.0);
        // row 2 and column 2 empty
        assert_eq!(a.factor(), Err(2));
    }

    #[test]
    fn entries_outside_the_band_are_refused() {
        let mut a = BandMatrix::zeros(5, 1, 2);
        assert!(a.set(3, 4, 1.0) && a.set(4, 3, 1.0));
        assert!(!a.set(4, 2, 1.0) && !a.set(0, 3, 1.0));
        assert_eq!(a.get(4, 2), 0.0);
    }
}
