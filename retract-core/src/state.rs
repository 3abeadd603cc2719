//! Typed data: derivative data ([`Jet`]) and Hamiltonian states ([`State`]) by blocks.
//!
//! Both are $2nk$ numbers, and the runtime steps flat vectors `SVector<f64, S>`, $S = 2nk$:
//!
//! - a [`Jet`] is the derivative data $(q, q', \dots, q^{(2k-1)})$ at one time, the argument
//!   of the Legendre map;
//! - a [`State`] is $z = (x, p)$ with $x_j = q^{(j)}$ ($j < k$) and the Ostrogradsky momenta
//!   $p_{k-1} = \partial L/\partial q^{(k)}$,
//!   $p_{j-1} = \partial L/\partial q^{(j)} - D p_j$ ($j = k-1, \dots, 1$).
//!
//! The only way from one to the other is [`State::from_jet`], which runs the Legendre map, so
//! derivative data cannot be stepped as if it were a state by mistake. The accessors name the
//! blocks: [`State::q`], [`State::derivative`] ($q^{(j)}$), [`State::momentum`] ($p_j$),
//! [`State::top_derivative`] ($u = q^{(k)}$). [`State::to_vector`] and
//! [`State::from_vector`] convert to and from the flat layout
//! $z = (x_0, \dots, x_{k-1}, p_0, \dots, p_{k-1})$ of [`crate::LiftedSystem`].
//!
//! # Example
//! For $L = \tfrac12|q''|^2$ the momenta are $p_1 = q''$ and $p_0 = -q'''$:
//! ```
//! use retract_core::models::PlanarBarrier;
//! use retract_core::state::{Jet, State};
//! use retract_core::StepOptions;
//!
//! let system = PlanarBarrier { tau: 0.0, radius: 1.0, mass: 1.0 };
//! // q, q', q'', q''' of a point in the plane
//! let jet = Jet::new(&[[2.0, 0.0], [1.0, 0.5], [0.2, 0.0], [0.1, -0.3]])?;
//! let z0 = State::from_jet(&system, &jet)?;
//! assert_eq!(z0.momentum(1), Some([0.2, 0.0].into())); // p_1 = q''
//! assert_eq!(z0.momentum(0), Some([-0.1, 0.3].into())); // p_0 = -q'''
//! let (z1, _) = z0.step(&system, 0.1, &StepOptions::default())?;
//! // the midpoint step: q(h) = q + h q' + h^2/2 p_1 - h^3/4 p_0
//! assert!((z1.q()[0] - (2.0 + 0.1 + 0.005 * 0.2 + 0.00025 * 0.1)).abs() < 1e-14);
//! # Ok::<(), retract_core::Error>(())
//! ```

use nalgebra::SVector;

use crate::scheme::lifted::{Blocks, join, split};
use crate::scheme::step::StepReport;
use crate::{Error, Lagrangian, LiftedSystem, StepOptions};

/// Derivative data $(q, q', \dots, q^{(2k-1)})$ of a curve at one time, $K = k$ blocks below
/// the top derivative ([`Self::lower`]) and $K$ from it on ([`Self::upper`]).
///
/// With the `serde` feature: `{"lower": [[q], [q'], ...], "upper": [...]}`, each block a
/// list of $n$ numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Jet<const N: usize, const K: usize> {
    /// $(q, q', \dots, q^{(k-1)})$.
    #[cfg_attr(feature = "serde", serde(with = "blocks_serde"))]
    pub lower: Blocks<N, K>,
    /// $(q^{(k)}, \dots, q^{(2k-1)})$.
    #[cfg_attr(feature = "serde", serde(with = "blocks_serde"))]
    pub upper: Blocks<N, K>,
}

fn finite_blocks<const N: usize, const K: usize>(blocks: &Blocks<N, K>) -> bool {
    blocks.iter().all(|b| b.iter().all(|v| v.is_finite()))
}

impl<const N: usize, const K: usize> Jet<N, K> {
    /// The jet with `derivatives[j]` $= q^{(j)}$, $j = 0, \dots, 2k-1$.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] unless there are exactly $2k$ rows, all finite.
    pub fn new(derivatives: &[[f64; N]]) -> Result<Self, Error> {
        if derivatives.len() != 2 * K {
            return Err(Error::InvalidArgument {
                name: "derivatives",
                requirement: "a jet holds q, q', ..., q^(2k-1): exactly 2k rows",
            });
        }
        let block = |j: usize| SVector::<f64, N>::from(derivatives[j]);
        let jet = Self {
            lower: core::array::from_fn(block),
            upper: core::array::from_fn(|j| block(K + j)),
        };
        jet.checked()
    }

    fn checked(self) -> Result<Self, Error> {
        if finite_blocks(&self.lower) && finite_blocks(&self.upper) {
            Ok(self)
        } else {
            Err(Error::InvalidArgument {
                name: "jet",
                requirement: "the derivative data must be finite",
            })
        }
    }

    /// The jet whose flat layout is `v` $= (q, q', \dots, q^{(2k-1)})$ in blocks of $n$ (the
    /// argument of [`LiftedSystem::legendre`]); `S` $= 2nk$ is
    /// checked at compile time.
    pub fn from_vector<const S: usize>(v: &SVector<f64, S>) -> Self {
        let (lower, upper) = split::<N, K, S>(v);
        Self { lower, upper }
    }

    /// The flat layout $(q, q', \dots, q^{(2k-1)})$, the inverse of [`Self::from_vector`].
    pub fn to_vector<const S: usize>(&self) -> SVector<f64, S> {
        join::<N, K, S>(&self.lower, &self.upper)
    }

    /// $q^{(j)}$, or `None` for $j \ge 2k$.
    pub fn derivative(&self, j: usize) -> Option<SVector<f64, N>> {
        self.lower
            .get(j)
            .or_else(|| self.upper.get(j.checked_sub(K)?))
            .copied()
    }
}

/// A Hamiltonian state $z = (x, p)$ of the lifted scheme, by blocks: $x_j = q^{(j)}$ and the
/// Ostrogradsky momenta $p_j$, $j < k$.
///
/// With the `serde` feature: `{"x": [[q], [q'], ...], "p": [[p_0], ...]}`, each block a list
/// of $n$ numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct State<const N: usize, const K: usize> {
    /// $x = (q, q', \dots, q^{(k-1)})$.
    #[cfg_attr(feature = "serde", serde(with = "blocks_serde"))]
    pub x: Blocks<N, K>,
    /// $p = (p_0, \dots, p_{k-1})$.
    #[cfg_attr(feature = "serde", serde(with = "blocks_serde"))]
    pub p: Blocks<N, K>,
}

impl<const N: usize, const K: usize> State<N, K> {
    /// The Legendre map: $x_j = q^{(j)}$ and the Ostrogradsky momenta
    /// $p_{k-1} = \partial L/\partial q^{(k)}$,
    /// $p_{j-1} = \partial L/\partial q^{(j)} - D p_j$, from the jet's derivative data.
    ///
    /// # Errors
    /// [`Error::NonFinite`] when a momentum is not finite (a jet outside the domain of $L$).
    pub fn from_jet<L>(system: &L, jet: &Jet<N, K>) -> Result<Self, Error>
    where
        L: Lagrangian<N, K> + ?Sized,
    {
        let state = Self {
            x: jet.lower,
            p: system.momenta(&jet.lower, &jet.upper),
        };
        if finite_blocks(&state.x) && finite_blocks(&state.p) {
            Ok(state)
        } else {
            Err(Error::NonFinite {
                iteration: 0,
                location: "momenta of the Legendre map",
            })
        }
    }

    /// The state whose flat layout is `z` $= (x_0, \dots, x_{k-1}, p_0, \dots, p_{k-1})$;
    /// `S` $= 2nk$ is checked at compile time.
    pub fn from_vector<const S: usize>(z: &SVector<f64, S>) -> Self {
        let (x, p) = split::<N, K, S>(z);
        Self { x, p }
    }

    /// The flat layout $z = (x, p)$ that [`crate::step()`] and [`crate::trajectory`] take.
    pub fn to_vector<const S: usize>(&self) -> SVector<f64, S> {
        join::<N, K, S>(&self.x, &self.p)
    }

    /// The configuration $q = x_0$.
    pub fn q(&self) -> SVector<f64, N> {
        self.x[0]
    }

    /// $x_j = q^{(j)}$, or `None` for $j \ge k$ (the top derivative is
    /// [`Self::top_derivative`]).
    pub fn derivative(&self, j: usize) -> Option<SVector<f64, N>> {
        self.x.get(j).copied()
    }

    /// The momentum $p_j$, or `None` for $j \ge k$.
    pub fn momentum(&self, j: usize) -> Option<SVector<f64, N>> {
        self.p.get(j).copied()
    }

    /// The top derivative $u = q^{(k)}$ that solves $p_{k-1} = \partial L/\partial u\thinspace(x, u)$
    /// ([`Lagrangian::top_derivative`], from $u = 0$).
    ///
    /// # Errors
    /// As [`Lagrangian::top_derivative`].
    pub fn top_derivative<L>(&self, system: &L) -> Result<SVector<f64, N>, Error>
    where
        L: Lagrangian<N, K> + ?Sized,
    {
        system.top_derivative(&self.x, &self.p[K - 1], &SVector::zeros())
    }

    /// One step $z_0 \mapsto z_1$ of [`crate::step()`] from this state, as a state (`S`
    /// $= 2nk$ and `M` $= S + n$ are those of the system's [`LiftedSystem`] implementation).
    ///
    /// # Errors
    /// As [`crate::step()`].
    pub fn step<Sys, const S: usize, const M: usize>(
        &self,
        system: &Sys,
        h: f64,
        options: &StepOptions,
    ) -> Result<(Self, StepReport), Error>
    where
        Sys: LiftedSystem<S, M> + ?Sized,
    {
        crate::scheme::step::step(system, &self.to_vector::<S>(), h, options)
            .map(|(z, report)| (Self::from_vector(&z), report))
    }

    /// `steps` steps of [`crate::trajectory`] from this state ([`crate::Trajectory::state`]
    /// gives its states back as [`State`]s).
    ///
    /// # Errors
    /// As [`crate::trajectory`]: the states computed before the failure, and the failure.
    #[cfg(feature = "std")]
    pub fn trajectory<Sys, const S: usize, const M: usize>(
        &self,
        system: &Sys,
        h: f64,
        steps: usize,
        options: &StepOptions,
    ) -> Result<crate::Trajectory<S>, crate::Interrupted<S>>
    where
        Sys: LiftedSystem<S, M> + ?Sized,
    {
        crate::scheme::step::trajectory(system, &self.to_vector::<S>(), h, steps, options)
    }
}

// (here rather than beside `Trajectory`, so that the schemes do not import the states)
#[cfg(feature = "std")]
impl<const S: usize> crate::Trajectory<S> {
    /// State $z_i$ by blocks ([`State`]: $q^{(j)}$, $p_j$ by name), or `None` past the end;
    /// `S` $= 2nk$ is checked at compile time.
    pub fn state<const N: usize, const K: usize>(&self, i: usize) -> Option<State<N, K>> {
        self.states.get(i).map(State::from_vector)
    }
}

/// [`Blocks`] as a list of $K$ blocks (serde implements arrays only up to a fixed length, not
/// for a const-generic one); deserializing needs no allocation.
#[cfg(feature = "serde")]
mod blocks_serde {
    use core::fmt;
    use core::marker::PhantomData;

    use nalgebra::SVector;
    use serde::de::{Error as _, SeqAccess, Visitor};
    use serde::ser::SerializeTuple;
    use serde::{Deserializer, Serializer};

    use crate::scheme::lifted::Blocks;

    pub fn serialize<S: Serializer, const N: usize, const K: usize>(
        blocks: &Blocks<N, K>,
        serializer: S,
    ) -> Result<S::Ok, S::Error> {
        let mut tuple = serializer.serialize_tuple(K)?;
        for block in blocks {
            tuple.serialize_element(block)?;
        }
        tuple.end()
    }

    struct BlocksVisitor<const N: usize, const K: usize>(PhantomData<Blocks<N, K>>);

    impl<'de, const N: usize, const K: usize> Visitor<'de> for BlocksVisitor<N, K> {
        type Value = Blocks<N, K>;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(f, "a list of {K} blocks of {N} numbers")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
            let mut blocks = [SVector::<f64, N>::zeros(); K];
            for (j, block) in blocks.iter_mut().enumerate() {
                *block = seq
                    .next_element()?
                    .ok_or_else(|| A::Error::invalid_length(j, &self))?;
            }
            if seq.next_element::<SVector<f64, N>>()?.is_some() {
                return Err(A::Error::invalid_length(K + 1, &self));
            }
            Ok(blocks)
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>, const N: usize, const K: usize>(
        deserializer: D,
    ) -> Result<Blocks<N, K>, D::Error> {
        deserializer.deserialize_tuple(K, BlocksVisitor(PhantomData))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::PlanarBarrier;

    #[test]
    fn jet_rejects_wrong_length_and_non_finite_data() {
        assert!(Jet::<2, 2>::new(&[[0.0; 2]; 3]).is_err());
        assert!(Jet::<2, 2>::new(&[[0.0, 0.0], [f64::NAN, 0.0], [0.0; 2], [0.0; 2]]).is_err());
        let jet = Jet::<2, 2>::new(&[[1.0, 2.0], [3.0, 4.0], [5.0, 6.0], [7.0, 8.0]]).unwrap();
        assert_eq!(jet.derivative(3), Some([7.0, 8.0].into()));
        assert_eq!(jet.derivative(4), None);
        let flat: SVector<f64, 8> = jet.to_vector();
        assert_eq!(flat.as_slice(), &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
        assert_eq!(Jet::from_vector(&flat), jet);
    }

    /// `from_jet` is the system's Legendre map, and the top derivative inverts
    /// $p_1 = \partial L/\partial u$ (for the disc system, $u = p_1 / m$).
    #[test]
    fn from_jet_is_the_legendre_map() {
        use crate::LiftedSystem;
        let system = PlanarBarrier {
            tau: 0.3,
            radius: 1.0,
            mass: 2.0,
        };
        let jet = Jet::<2, 2>::new(&[[2.0, 0.5], [1.0, -0.5], [0.2, 0.4], [0.1, -0.3]]).unwrap();
        let state = State::from_jet(&system, &jet).unwrap();
        let flat: SVector<f64, 8> = state.to_vector();
        assert_eq!(flat, system.legendre(&jet.to_vector()));
        assert_eq!(State::from_vector(&flat), state);
        let u = state.top_derivative(&system).unwrap();
        assert!((u - SVector::from([0.2, 0.4])).amax() < 1e-12, "{u}");
        assert_eq!(state.derivative(1), Some([1.0, -0.5].into()));
        assert_eq!(state.derivative(2), None);
        assert_eq!(state.momentum(2), None);
    }

    /// The typed step and trajectory are the flat ones: the same numbers, bit for bit.
    #[test]
    fn typed_step_and_trajectory_are_the_flat_ones() {
        let system = PlanarBarrier {
            tau: 0.3,
            radius: 1.0,
            mass: 2.0,
        };
        let options = StepOptions::default();
        let jet = Jet::<2, 2>::new(&[[2.0, 0.5], [1.0, -0.5], [0.2, 0.4], [0.1, -0.3]]).unwrap();
        let z0 = State::from_jet(&system, &jet).unwrap();
        let (typed, _) = z0.step(&system, 0.05, &options).unwrap();
        let (flat, _) = crate::step(&system, &z0.to_vector::<8>(), 0.05, &options).unwrap();
        assert_eq!(typed.to_vector::<8>(), flat);
        assert_ne!(typed, z0);
        let run = z0.trajectory(&system, 0.05, 3, &options).unwrap();
        assert_eq!(run.state::<2, 2>(1), Some(typed));
        assert_eq!(run.state::<2, 2>(0), Some(z0));
    }

    #[test]
    fn from_jet_reports_non_finite_momenta() {
        let system = PlanarBarrier {
            tau: 0.3,
            radius: 1.0,
            mass: f64::INFINITY,
        };
        let jet = Jet::<2, 2>::new(&[[2.0, 0.5], [1.0, -0.5], [0.2, 0.4], [0.1, -0.3]]).unwrap();
        assert!(matches!(
            State::from_jet(&system, &jet),
            Err(Error::NonFinite { .. })
        ));
    }

    /// A jet or a state read from JSON holds finite numbers only (JSON has no NaN), but
    /// hostile ones: each is refused by its use (the Legendre map, a step), never turned
    /// into a non-finite state.
    #[cfg(feature = "serde")]
    #[test]
    fn hostile_jets_and_states_from_json_are_refused_on_use() {
        let system = PlanarBarrier {
            tau: 0.3,
            radius: 1.0,
            mass: 2.0,
        };
        let jet = Jet::<2, 2>::new(&[[2.0, 0.5], [1.0, -0.5], [0.2, 0.4], [0.1, -0.3]]).unwrap();
        let valid_jet = serde_json::to_value(jet).unwrap();
        let state = State::from_jet(&system, &jet).unwrap();
        let valid_state = serde_json::to_value(state).unwrap();
        assert_eq!(
            serde_json::from_value::<State<2, 2>>(valid_state.clone()).unwrap(),
            state
        );
        // q'' = 1e308: the momentum m q'' overflows
        let mut value = valid_jet.clone();
        value["upper"][0][0] = 1e308.into();
        let read: Jet<2, 2> = serde_json::from_value(value).unwrap();
        assert!(State::from_jet(&system, &read).is_err());
        // NaN and infinity do not read (serde_json refuses them)
        for bad in ["NaN", "1e400"] {
            let text = valid_jet.to_string().replacen("2.0", bad, 1);
            assert!(serde_json::from_str::<Jet<2, 2>>(&text).is_err(), "{bad}");
        }
        // a state of huge numbers steps to an error or to a finite state, never to NaN
        let options = StepOptions::default();
        for (block, j, value) in [
            ("x", 0, 1e308),
            ("x", 1, 1e308),
            ("p", 1, -1e308),
            ("p", 0, 1e200),
        ] {
            let mut edited = valid_state.clone();
            edited[block][j][0] = value.into();
            let read: State<2, 2> = serde_json::from_value(edited).unwrap();
            if let Ok((next, _)) = read.step(&system, 0.01, &options) {
                let z: SVector<f64, 8> = next.to_vector();
                assert!(
                    z.iter().all(|v| v.is_finite()),
                    "{block}{j} = {value:e}: {z}"
                );
            }
        }
    }
}
