//! The step maps of the condensed Newton direction: each step's linearised map
//! $\delta w_i = \Phi_i \delta z_i + c_i$ (a dense LU per step, or the cached factors of a
//! [`ReducedScheme`]); the sweeps that eliminate the steps' unknowns with them, leaving an
//! $nk \times nk$ system for the free initial momenta, are `condensed_direction` in the root
//! finder. Imports nothing of the root finder.

use nalgebra::{SMatrix, SVector};

use crate::{Error, LiftedSystem, ReducedFactors, ReducedScheme};
/// The linearisation of step $i$ from $z_i$, $w_i$ and the step's residual $F_i$, written into
/// the last argument in place (no copy of the map); `false` if singular.
pub(super) type StepMap<'a, const S: usize, const M: usize> =
    &'a dyn Fn(&SVector<f64, S>, &SVector<f64, M>, &SVector<f64, M>, &mut Linearized<S, M>) -> bool;

/// The linearised map of one step at the current iterate, $\delta w = \Phi \delta z + c$, with
/// $\Phi$ and $c$ solving $\partial_z F\thinspace \delta z + \partial_w F\thinspace \delta w = -F$.
#[derive(Clone)]
pub(super) struct Linearized<const S: usize, const M: usize> {
    phi: SMatrix<f64, M, S>,
    c: SVector<f64, M>,
}

impl<const S: usize, const M: usize> Linearized<S, M> {
    /// $\Phi = 0$, $c = 0$: a slot for [`StepMap`] to fill.
    pub(super) fn zeros() -> Self {
        Self {
            phi: SMatrix::zeros(),
            c: SVector::zeros(),
        }
    }

    /// $\Phi\thinspace \delta z + c$.
    pub(super) fn affine(&self, dz: &SVector<f64, S>) -> SVector<f64, M> {
        let mut out = self.c;
        self.add_product(&mut out, dz);
        out
    }

    /// The $z$ rows of $\Phi x$.
    pub(super) fn linear_z(&self, x: &SVector<f64, S>) -> SVector<f64, S> {
        let mut out = SVector::<f64, S>::zeros();
        self.add_product(&mut out, x);
        out
    }

    /// `out += ` the first `LEN` rows of $\Phi x$, column by column over slices of constant
    /// length: the inner loop runs down a contiguous column and vectorises (nalgebra's generic
    /// product on a row view does not).
    fn add_product<const LEN: usize>(&self, out: &mut SVector<f64, LEN>, x: &SVector<f64, S>) {
        for (column, &weight) in self.phi.as_slice().chunks_exact(M).zip(x.iter()) {
            for (o, p) in out.as_mut_slice().iter_mut().zip(column) {
                *o += p * weight;
            }
        }
    }
}

/// $\Phi = -(\partial_w F)^{-1} \partial_z F$ and $c = -(\partial_w F)^{-1} F$ by one dense LU.
pub(super) fn general_step_map<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z: &SVector<f64, S>,
    w: &SVector<f64, M>,
    f: &SVector<f64, M>,
    h: f64,
    theta: f64,
    out: &mut Linearized<S, M>,
) -> bool
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    out.phi = -system.jacobian_initial(z, w, h, theta);
    out.c = -f;
    crate::linalg::solve_pair_in_place(system.jacobian(z, w, h, theta), &mut out.phi, &mut out.c)
}

/// The step maps of a [`ReducedScheme`]. With $F = A w + B z + n(y)$,
/// $y = \theta E w + (1-\theta) E z$, $N = \partial n / \partial y$ at the iterate,
/// $g = A^{-1} F$ and $H = A^{-1} N$, the linearised step is
/// $(I + \theta E H)\thinspace \delta y = G \delta z - \theta E g$ and
/// $\delta w = T \delta z - g - H \delta y$ (notation of [`crate::reduced`]): a rank-$R$ change
/// of the constant map $T$, formed densely into the step's slot. (Kept factored, as $H$,
/// $(I + \theta E H)^{-1}$ and $g$, and applied column by column over the nonzero rows of $T$,
/// the maps made the SE(2) solve 1.5x slower: the dense products vectorise, the factored ones
/// do not, and they need more arithmetic per column than they save in forming $\Phi$.)
pub(super) struct ReducedStepMap<'a, Sys: ?Sized, const S: usize, const M: usize, const R: usize> {
    system: &'a Sys,
    factors: ReducedFactors<S, M, R>,
    a_inv: SMatrix<f64, M, M>,
}

impl<'a, Sys, const S: usize, const M: usize, const R: usize> ReducedStepMap<'a, Sys, S, M, R>
where
    Sys: ReducedScheme<S, M, R> + ?Sized,
{
    pub(super) fn new(system: &'a Sys, h: f64, theta: f64) -> Result<Self, Error> {
        let factors = ReducedFactors::new(system, h, theta)?;
        let a_inv = crate::linalg::solve(
            &system.linear_part(h, theta),
            &SMatrix::<f64, M, M>::identity(),
        )
        .ok_or(Error::SingularJacobian { iteration: 0 })?;
        Ok(Self {
            system,
            factors,
            a_inv,
        })
    }

    pub(super) fn linearize(
        &self,
        z: &SVector<f64, S>,
        w: &SVector<f64, M>,
        f: &SVector<f64, M>,
        out: &mut Linearized<S, M>,
    ) -> bool {
        let ReducedFactors { h, theta, .. } = self.factors;
        let y = SVector::<f64, R>::from_fn(|m, _| {
            let c = Sys::CORE[m];
            (1.0 - theta) * z[c] + theta * w[c]
        });
        let n = self.system.forcing_jacobian(&y, h, theta);
        // g = A^{-1} F over the blocks of A (A^{-1} is block diagonal after permutation)
        let mut g = SVector::<f64, M>::zeros();
        for &(rows, cols) in Sys::BLOCKS {
            for &c in cols {
                g[c] = rows.iter().map(|&r| self.a_inv[(c, r)] * f[r]).sum();
            }
        }
        let mut hm = SMatrix::<f64, M, R>::zeros();
        for &q in Sys::FORCED {
            for m in 0..R {
                let nq = n[(q, m)];
                if nq != 0.0 {
                    for r in 0..M {
                        hm[(r, m)] += self.a_inv[(r, q)] * nq;
                    }
                }
            }
        }
        let mut lhs = SMatrix::<f64, R, R>::identity();
        let mut inverse = SMatrix::<f64, R, R>::identity();
        let mut x0 = SVector::<f64, R>::zeros();
        for (m, &c) in Sys::CORE.iter().enumerate() {
            for l in 0..R {
                lhs[(m, l)] += theta * hm[(c, l)];
            }
            x0[m] = -theta * g[c];
        }
        // delta y = X delta z + x0 with X = (I + theta E H)^{-1} G, so Phi = T - H X and
        // c = -g - H x0 (the inverse, not X, from the small solve: its finiteness check then
        // reads R (R + 1) numbers, not R (S + 1); the direction's is the final word)
        if !crate::linalg::solve_small_pair_in_place(lhs, &mut inverse, &mut x0) {
            return false;
        }
        let x = inverse * self.factors.g;
        out.phi.copy_from(&self.factors.t);
        out.c = -g;
        let h_columns = hm.as_slice().chunks_exact(M);
        for (m, h_column) in h_columns.enumerate() {
            for (phi_column, &weight) in out
                .phi
                .as_mut_slice()
                .chunks_exact_mut(M)
                .zip(x.row(m).iter())
            {
                for (p, hr) in phi_column.iter_mut().zip(h_column) {
                    *p -= hr * weight;
                }
            }
            for (c, hr) in out.c.iter_mut().zip(h_column) {
                *c -= hr * x0[m];
            }
        }
        true
    }
}
