//! The factors of the reduced step block by block: for each irreducible block of $A$ (rows
//! $\rho$, columns $\gamma$), one LU factorisation of $A_{\rho\gamma}$ serves the solve for
//! the block's rows of $T$ and $A^{-1}$ (unless the closed form gives them), their residuals
//! and the solve for their corrections ([`super::ReducedFactors`], module docs of
//! [`super`]).
//!
//! $A$ is block diagonal after the permutation, so row $r \in \rho$ of $A$ has its nonzeros
//! in the columns $\gamma$ only, and $T_{\gamma} = -A_{\rho\gamma}^{-1} B_{\rho}$,
//! $(A^{-1})_{\gamma q} = A_{\rho\gamma}^{-1} e_q$ for the forced rows $q \in \rho$ (the other
//! entries of $A^{-1}$ at $\gamma$ are zero), and the residuals
//! $A_{\rho\gamma} T_{\gamma} + B_{\rho}$, $A_{\rho\gamma} (A^{-1})_{\gamma q} - e_q$ are the
//! block's rows of those of the whole matrices.

use nalgebra::SMatrix;

use super::{ClosedForm, Dot2, ReducedFactors, ReducedScheme, Split};
use crate::Error;
use crate::numeric::linalg::{Pivots, factor_overwriting, solve_factored};

/// Relative residual above which a rational closed form is refused for a block (its
/// elimination divided by a nearly vanishing pivot), as a fraction of
/// $\max_i \sum_j |a_{ij}| |x_j| + |y_i|$ over the column.
const CLOSED_FORM_TOLERANCE: f64 = 1e-10;

/// The rows and the columns of one irreducible block of $A$ ([`ReducedScheme::BLOCKS`]).
#[derive(Clone, Copy)]
pub(super) struct Block<'a> {
    pub(super) rows: &'a [usize],
    pub(super) cols: &'a [usize],
}

/// The buffers of one block's factorisation, reused by every block (each entry read is
/// written first for that block).
pub(super) struct BlockWork<const S: usize, const M: usize> {
    /// The LU factors of the block of $A$ (its leading $n \times n$ entries).
    lu: SMatrix<f64, M, M>,
    pivots: Pivots<M>,
    /// The block's columns of $T$ (the right-hand sides $-B$, then the solutions), then the
    /// right-hand sides of their corrections; the $k$-th is column `t_cols[k]` of $T$.
    t_part: SMatrix<f64, M, S>,
    /// As `t_part` for the forced columns of $A^{-1}$ in the block's rows (`inverse_cols`).
    inverse_part: SMatrix<f64, M, M>,
    t_cols: [usize; S],
    t_count: usize,
    inverse_cols: [usize; M],
    inverse_count: usize,
}

impl<const S: usize, const M: usize> BlockWork<S, M> {
    pub(super) fn new() -> Self {
        Self {
            lu: SMatrix::zeros(),
            pivots: Pivots::new(),
            t_part: SMatrix::zeros(),
            inverse_part: SMatrix::zeros(),
            t_cols: [0; S],
            t_count: 0,
            inverse_cols: [0; M],
            inverse_count: 0,
        }
    }

    /// Writes the block's rows of $T$ and $A^{-1}$ into `f` (kept from the closed form
    /// `closed` where it is accepted for the block: finite, and for a rational one solving
    /// the block to [`CLOSED_FORM_TOLERANCE`]; else by LU, the closed form's entries in the
    /// block's rows cleared), and their corrections. `f.t` and the forced columns of
    /// `f.a_inv` hold the closed form's values (zero where there is none), `f.t_lo` and
    /// `f.a_inv_lo` zeros.
    ///
    /// Returns the largest magnitude of the block's entries of $T$ and $A^{-1}$.
    ///
    /// # Errors
    /// [`Error::SingularJacobian`] (iteration 0) if the block is not square, is singular, or
    /// a solve is not finite.
    pub(super) fn factor<Sys, const R: usize>(
        &mut self,
        a: &SMatrix<f64, M, M>,
        b: &SMatrix<f64, M, S>,
        block: Block<'_>,
        closed: ClosedForm,
        f: &mut ReducedFactors<S, M, R>,
    ) -> Result<f64, Error>
    where
        Sys: ReducedScheme<S, M, R> + ?Sized,
    {
        let singular = Error::SingularJacobian { iteration: 0 };
        let Block { rows, cols } = block;
        let n = rows.len();
        if n != cols.len() || n > M {
            return Err(singular);
        }
        self.select_columns::<Sys, R>(b, block, closed, f);
        let accepted = match closed {
            ClosedForm::None => false,
            ClosedForm::Polynomial => block_finite::<Sys, S, M, R>(f, cols),
            ClosedForm::Rational => {
                block_finite::<Sys, S, M, R>(f, cols) && self.closed_form_fits(a, b, block, f)
            }
        };
        for (j, &c) in cols.iter().enumerate() {
            for (i, &r) in rows.iter().enumerate() {
                self.lu[(i, j)] = a[(r, c)];
            }
        }
        if !factor_overwriting(&mut self.lu, n, &mut self.pivots, &mut [], &mut []) {
            return Err(singular);
        }
        if !accepted {
            self.solve::<Sys, R>(b, block, closed, f)?;
        }
        let (any, largest) = self.residuals(a, b, block, f);
        if any {
            if !self.solve_parts(n) {
                return Err(singular);
            }
            self.scatter(cols, (&mut f.t_lo, &mut f.a_inv_lo));
        }
        Ok(largest)
    }

    /// The columns of $T$ the block has nonzeros in (those of $B$ nonzero on its rows, and
    /// those of a closed form nonzero on its columns), and the forced rows among its rows.
    fn select_columns<Sys, const R: usize>(
        &mut self,
        b: &SMatrix<f64, M, S>,
        Block { rows, cols }: Block<'_>,
        closed: ClosedForm,
        f: &ReducedFactors<S, M, R>,
    ) where
        Sys: ReducedScheme<S, M, R> + ?Sized,
    {
        self.t_count = 0;
        for c in 0..S {
            let column = b.column(c);
            let touched = rows.iter().any(|&r| column[r] != 0.0)
                || (closed != ClosedForm::None && cols.iter().any(|&k| f.t[(k, c)] != 0.0));
            if touched {
                self.t_cols[self.t_count] = c;
                self.t_count += 1;
            }
        }
        self.inverse_count = 0;
        for &q in Sys::FORCED {
            if rows.contains(&q) {
                self.inverse_cols[self.inverse_count] = q;
                self.inverse_count += 1;
            }
        }
    }

    /// Whether the closed form's block of $T$ and $A^{-1}$ solves $A T = -B$ and
    /// $A\thinspace a^{-1}_q = e_q$ on the block, column by column to
    /// [`CLOSED_FORM_TOLERANCE`].
    fn closed_form_fits<const R: usize>(
        &self,
        a: &SMatrix<f64, M, M>,
        b: &SMatrix<f64, M, S>,
        Block { rows, cols }: Block<'_>,
        f: &ReducedFactors<S, M, R>,
    ) -> bool {
        let fits = |x: &dyn Fn(usize) -> f64, y: &dyn Fn(usize) -> f64| {
            let (mut residual, mut scale) = (0.0f64, 0.0f64);
            for (i, &r) in rows.iter().enumerate() {
                let (mut sum, mut size) = (y(i), y(i).abs());
                for (j, &k) in cols.iter().enumerate() {
                    let term = a[(r, k)] * x(j);
                    sum += term;
                    size += term.abs();
                }
                residual = residual.max(sum.abs());
                scale = scale.max(size);
            }
            residual <= CLOSED_FORM_TOLERANCE * scale
        };
        self.t_cols[..self.t_count]
            .iter()
            .all(|&c| fits(&|j| f.t[(cols[j], c)], &|i| b[(rows[i], c)]))
            && self.inverse_cols[..self.inverse_count]
                .iter()
                .all(|&q| fits(&|j| f.a_inv[(cols[j], q)], &|i| -unit(rows[i], q)))
    }

    /// Solves for the block's rows of $T$ and of the forced columns of $A^{-1}$ with the
    /// factors of the block, clearing a refused closed form's entries in those rows first.
    fn solve<Sys, const R: usize>(
        &mut self,
        b: &SMatrix<f64, M, S>,
        Block { rows, cols }: Block<'_>,
        closed: ClosedForm,
        f: &mut ReducedFactors<S, M, R>,
    ) -> Result<(), Error>
    where
        Sys: ReducedScheme<S, M, R> + ?Sized,
    {
        for (k, &c) in self.t_cols[..self.t_count].iter().enumerate() {
            for (i, &r) in rows.iter().enumerate() {
                self.t_part[(i, k)] = -b[(r, c)];
            }
        }
        for (k, &q) in self.inverse_cols[..self.inverse_count].iter().enumerate() {
            for (i, &r) in rows.iter().enumerate() {
                self.inverse_part[(i, k)] = unit(r, q);
            }
        }
        if !self.solve_parts(rows.len()) {
            return Err(Error::SingularJacobian { iteration: 0 });
        }
        if closed != ClosedForm::None {
            for &k in cols {
                for c in 0..S {
                    f.t[(k, c)] = 0.0;
                }
                for &q in Sys::FORCED {
                    f.a_inv[(k, q)] = 0.0;
                }
            }
        }
        self.scatter(cols, (&mut f.t, &mut f.a_inv));
        Ok(())
    }

    /// Solves $A_{\rho\gamma} X = Y$ in place for the columns in use of `t_part` and
    /// `inverse_part` with the block's factors (of size `n`); whether all are finite.
    fn solve_parts(&mut self, n: usize) -> bool {
        let (t_end, inverse_end) = (self.t_count * M, self.inverse_count * M);
        let (lu, pivots) = (&self.lu, &self.pivots);
        solve_factored(lu, n, pivots, &mut self.t_part.as_mut_slice()[..t_end])
            && solve_factored(
                lu,
                n,
                pivots,
                &mut self.inverse_part.as_mut_slice()[..inverse_end],
            )
    }

    /// Writes the solved columns into the block's rows (its columns $\gamma$) of `t` and
    /// `a_inv`.
    fn scatter(
        &self,
        cols: &[usize],
        (t, a_inv): (&mut SMatrix<f64, M, S>, &mut SMatrix<f64, M, M>),
    ) {
        for (j, &k) in cols.iter().enumerate() {
            for (l, &c) in self.t_cols[..self.t_count].iter().enumerate() {
                t[(k, c)] = self.t_part[(j, l)];
            }
            for (l, &q) in self.inverse_cols[..self.inverse_count].iter().enumerate() {
                a_inv[(k, q)] = self.inverse_part[(j, l)];
            }
        }
    }

    /// Writes the negated residuals $-(A_{\rho\gamma} T_{\gamma} + B_{\rho})$ and
    /// $-(A_{\rho\gamma} (A^{-1})_{\gamma q} - e_q)$ of the rounded factors, each summed
    /// compensated ([`residual_lanes`], [`LANES`] columns at a time), into the
    /// right-hand-side buffers. Returns whether any is nonzero, and the largest magnitude of
    /// the block's entries of $T$ and $A^{-1}$ (every nonzero of them is read here).
    fn residuals<const R: usize>(
        &mut self,
        a: &SMatrix<f64, M, M>,
        b: &SMatrix<f64, M, S>,
        Block { rows, cols }: Block<'_>,
        f: &ReducedFactors<S, M, R>,
    ) -> (bool, f64) {
        let (t_count, total) = (self.t_count, self.t_count + self.inverse_count);
        let (mut any, mut largest) = (false, 0.0f64);
        // x[j][l]: the entry at the block's column j of the group's l-th column (zero padding)
        let mut x = [[Split::new(0.0); LANES]; M];
        for start in (0..total).step_by(LANES) {
            let column = |l: usize| match start + l {
                m if m < t_count => Some(Ok(self.t_cols[m])),
                m if m < total => Some(Err(self.inverse_cols[m - t_count])),
                _ => None,
            };
            for (x, &k) in x.iter_mut().zip(cols) {
                for (l, x) in x.iter_mut().enumerate() {
                    let value = match column(l) {
                        Some(Ok(c)) => f.t[(k, c)],
                        Some(Err(q)) => f.a_inv[(k, q)],
                        None => 0.0,
                    };
                    largest = largest.max(value.abs());
                    *x = Split::new(value);
                }
            }
            for (i, &r) in rows.iter().enumerate() {
                let y = core::array::from_fn(|l| match column(l) {
                    Some(Ok(c)) => b[(r, c)],
                    Some(Err(q)) => -unit(r, q),
                    None => 0.0,
                });
                let sums = residual_lanes(a, r, cols, &x, y);
                for (l, sum) in sums.into_iter().enumerate() {
                    any |= sum != 0.0;
                    match start + l {
                        m if m < t_count => self.t_part[(i, m)] = -sum,
                        m if m < total => self.inverse_part[(i, m - t_count)] = -sum,
                        _ => {}
                    }
                }
            }
        }
        (any, largest)
    }
}

/// Entry $(r, q)$ of the identity.
fn unit(r: usize, q: usize) -> f64 {
    if r == q { 1.0 } else { 0.0 }
}

/// Whether the closed form's entries in the block's rows (its columns `cols`) of $T$ and of
/// the forced columns of $A^{-1}$ are finite.
fn block_finite<Sys, const S: usize, const M: usize, const R: usize>(
    f: &ReducedFactors<S, M, R>,
    cols: &[usize],
) -> bool
where
    Sys: ReducedScheme<S, M, R> + ?Sized,
{
    cols.iter().all(|&k| {
        (0..S).all(|c| f.t[(k, c)].is_finite())
            && Sys::FORCED.iter().all(|&q| f.a_inv[(k, q)].is_finite())
    })
}

/// Columns summed together by [`residual_lanes`] (independent sums, so that they vectorise).
const LANES: usize = 4;

/// $\sum_j a_{r, \gamma_j} x_{j l} + y_l$ for the [`LANES`] columns $l$, over the block's
/// columns $\gamma$ (`cols`; `x[j]` the entries at $\gamma_j$),
/// each compensated as [`Dot2`]: every product's and addition's rounding error summed apart
/// and added once at the end. The nonzeros of the row that are powers of two ($\pm 1$ among
/// them) come first: their products are exact (unless they underflow), so only their sums
/// are compensated.
#[inline(always)]
fn residual_lanes<const M: usize>(
    a: &SMatrix<f64, M, M>,
    r: usize,
    cols: &[usize],
    x: &[[Split; LANES]; M],
    y: [f64; LANES],
) -> [f64; LANES] {
    // a normal double with a zero significand field is a power of two
    let power_of_two = |v: f64| v.is_normal() && v.to_bits() & ((1 << 52) - 1) == 0;
    let mut sums = y.map(Dot2::exact);
    for exact in [true, false] {
        for (&k, x) in cols.iter().zip(x) {
            let v = a[(r, k)];
            if v == 0.0 || power_of_two(v) != exact {
                continue;
            }
            let v = Split::new(v);
            for (sum, &x) in sums.iter_mut().zip(x) {
                if exact {
                    sum.add_exact(v.value * x.value);
                } else {
                    sum.add_split_product(v, x);
                }
            }
        }
    }
    sums.map(Dot2::value)
}
