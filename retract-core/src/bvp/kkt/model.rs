//! The data of the quadratic subproblem: each stage's model ([`StageModel`]: Hessian,
//! gradient, defect, stage equalities), the linear data of a solve ([`StageLinear`]) and the
//! ends of the horizon ([`Terminal`]).

use nalgebra::{SMatrix, SVector};

use crate::newton::all_finite;

/// One stage's quadratic model: the Hessian blocks and gradient of $h\thinspace L$ in
/// $y = (x_\theta, u)$ (the Hessian of the Lagrangian, with the constraints' curvature), the
/// defect $c_i$, and the stage's equality constraints $g(y) = 0$: `constraints` rows of
/// `cx` $= \partial g/\partial x_\theta$, `cu` $= \partial g/\partial u$ and `value` $= g$.
#[derive(Clone, Debug)]
pub(crate) struct StageModel<const N: usize, const X: usize> {
    pub hxx: SMatrix<f64, X, X>,
    /// $\partial^2 / \partial u \partial x_\theta$ ($N \times X$).
    pub hux: SMatrix<f64, N, X>,
    pub huu: SMatrix<f64, N, N>,
    pub gx: SVector<f64, X>,
    pub gu: SVector<f64, N>,
    pub defect: SVector<f64, X>,
    pub constraints: usize,
    pub cx: SMatrix<f64, N, X>,
    pub cu: SMatrix<f64, N, N>,
    pub value: SVector<f64, N>,
    /// Terms of the node $x_i$ itself (the barrier of the inequalities placed at the node):
    /// their Hessian and gradient in $\delta x_i$, added to $Q_{xx}$ and $q_x$.
    pub node: Option<NodeTerms<X>>,
}

impl<const N: usize, const X: usize> StageModel<N, X> {
    /// Whether every entry of the Hessian blocks, the gradient, the equality rows and the node
    /// terms is finite (each a vectorised sum of 0 * entry: nalgebra's `sum` is one chain of
    /// dependent additions, a fifth of an SQP iteration on the SE(2) scene).
    #[inline]
    pub fn is_finite(&self) -> bool {
        let node =
            (self.node.as_ref()).is_none_or(|node| all_finite(&node.0) & all_finite(&node.1));
        all_finite(&self.hxx)
            & all_finite(&self.hux)
            & all_finite(&self.huu)
            & all_finite(&self.gx)
            & all_finite(&self.gu)
            & all_finite(&self.cx)
            & all_finite(&self.cu)
            & all_finite(&self.value)
            & node
    }
}

/// The Hessian and gradient in $\delta x_i$ of terms of a node $x_i$ itself.
pub(crate) type NodeTerms<const X: usize> = (SMatrix<f64, X, X>, SVector<f64, X>);

/// The linear data of one stage of a subproblem: the gradient $(l_x, l_u)$ in
/// $(\delta x_i, \delta u_i)$, the defect $c_i$ and the constraint offset $c_0$.
pub(crate) struct StageLinear<const N: usize, const X: usize> {
    pub lx: SVector<f64, X>,
    pub lu: SVector<f64, N>,
    pub defect: SVector<f64, X>,
    pub constraint: SVector<f64, N>,
}

/// The ends of the horizon: the Hessian of the terminal cost $\Phi(x_N)$ (the cost-to-go
/// $P_N$), which components of $x_N$ the goal fixes (1) or leaves free (0), and likewise of
/// $x_0$ for the start.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Terminal<const X: usize> {
    pub hessian: SMatrix<f64, X, X>,
    pub fixed: SVector<f64, X>,
    pub start_fixed: SVector<f64, X>,
}

impl<const X: usize> Terminal<X> {
    /// A goal fixing all of $x_N$, no terminal cost.
    #[cfg(test)]
    pub fn fixed_end() -> Self {
        Self {
            hessian: SMatrix::zeros(),
            fixed: SVector::repeat(1.0),
            start_fixed: SVector::repeat(1.0),
        }
    }

    /// The number of fixed components (rows of the terminal constraint).
    pub fn rows(&self) -> usize {
        self.fixed.iter().filter(|f| **f != 0.0).count()
    }
}
