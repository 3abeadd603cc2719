//! CSV export of trajectories, plans and boundary-value solutions (std only).
//!
//! Every file starts with a header naming every column, then one row per node $t_i = i h$.
//! For a system on $\mathbb{R}^n$ of order $k$ the columns are, in this order
//! ([`state_columns`]):
//!
//! | column | value |
//! |---|---|
//! | `t` | $t_i = i h$ |
//! | `q_c` | coordinate $c$ of $q$, $c = 0, \dots, n-1$ |
//! | `d{j}q_c` | coordinate $c$ of $q^{(j)}$, $1 \le j < k$ (`d1q_0` is $q_0'$) |
//! | `p{j}_c` | coordinate $c$ of the Ostrogradsky momentum $p_j$, $0 \le j < k$ |
//! | `u_c` | coordinate $c$ of the top derivative $u = q^{(k)}$ of the step from $t_i$ ([`Plan`], [`BvpSolution`] only; empty in the last row) |
//!
//! The numbers are written with Rust's shortest representation that parses back to the
//! same `f64` (`{}`; `NaN`, `inf`, `-inf` for the non-finite ones), so `str::parse::<f64>`
//! recovers every value exactly. Cells are separated by `,` and rows end with `\n`; nothing
//! is quoted (no name or number contains a comma).
//!
//! ```
//! use retract_core::models::PlanarBarrier;
//! use retract_core::{StepOptions, trajectory};
//!
//! let system = PlanarBarrier { tau: 0.0, radius: 1.0, mass: 1.0 };
//! let z0 = [2.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.1, 0.0].into();
//! let run = trajectory(&system, &z0, 0.1, 3, &StepOptions::default())?;
//! let mut csv = Vec::new();
//! run.write_csv::<2, 2>(&mut csv)?; // n = 2 coordinates, order k = 2
//! let text = String::from_utf8(csv)?;
//! let mut lines = text.lines();
//! assert_eq!(lines.next(), Some("t,q_0,q_1,d1q_0,d1q_1,p0_0,p0_1,p1_0,p1_1"));
//! assert_eq!(lines.next(), Some("0,2,0,0,1,0,0,0.1,0"));
//! assert_eq!(lines.count(), 3);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::io::{self, Write};

use nalgebra::SVector;

use crate::Trajectory;
use crate::bvp::Plan;
use crate::bvp::root_finder::BvpSolution;

/// The names of the $2nk$ state columns $z = (x, p)$ of a system on $\mathbb{R}^n$ of order
/// $k$: `q_c`, then `d{j}q_c` for $j = 1, \dots, k-1$, then `p{j}_c` for $j = 0, \dots, k-1$,
/// each for $c = 0, \dots, n-1$ (the flat layout of [`crate::State::to_vector`]).
///
/// ```
/// assert_eq!(
///     retract_core::output::state_columns(1, 3),
///     ["q_0", "d1q_0", "d2q_0", "p0_0", "p1_0", "p2_0"]
/// );
/// ```
pub fn state_columns(n: usize, k: usize) -> Vec<String> {
    let mut names = jet_columns(n, k);
    for j in 0..k {
        names.extend((0..n).map(|c| format!("p{j}_{c}")));
    }
    names
}

/// `q_c`, `d{j}q_c` ($1 \le j < k$): the columns of a jet $x = (q, \dots, q^{(k-1)})$.
fn jet_columns(n: usize, k: usize) -> Vec<String> {
    let mut names: Vec<String> = (0..n).map(|c| format!("q_{c}")).collect();
    for j in 1..k {
        names.extend((0..n).map(|c| format!("d{j}q_{c}")));
    }
    names
}

/// `u_c`: the columns of the top derivative.
fn top_columns(n: usize) -> Vec<String> {
    (0..n).map(|c| format!("u_{c}")).collect()
}

/// Writes the header `t,<columns>` and one row per entry of `rows` (`t`, then one cell per
/// column, `None` an empty cell), buffered.
fn write_table(
    out: impl Write,
    columns: &[String],
    rows: impl Iterator<Item = (f64, Vec<Option<f64>>)>,
) -> io::Result<()> {
    let mut out = io::BufWriter::new(out);
    write!(out, "t")?;
    for name in columns {
        write!(out, ",{name}")?;
    }
    writeln!(out)?;
    for (t, cells) in rows {
        if cells.len() != columns.len() {
            return Err(invalid(
                "a row has a different number of cells than the header",
            ));
        }
        write!(out, "{t}")?;
        for cell in cells {
            match cell {
                Some(v) => write!(out, ",{v}")?,
                None => write!(out, ",")?,
            }
        }
        writeln!(out)?;
    }
    out.flush()
}

/// The cells of the vectors `parts`, in order; a missing vector gives `width` empty cells.
fn cells(parts: &[(Option<&[f64]>, usize)]) -> Vec<Option<f64>> {
    parts
        .iter()
        .flat_map(|&(part, width)| match part {
            Some(values) => values.iter().map(|&v| Some(v)).collect::<Vec<_>>(),
            None => vec![None; width],
        })
        .collect()
}

fn invalid(message: &'static str) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

impl<const S: usize> Trajectory<S> {
    /// Writes the trajectory as CSV (see [`crate::output`]): the header
    /// `t,q_0,..,d1q_0,..,p0_0,..` ([`state_columns`]`(N, K)`), then one row
    /// $t_i, z_i$ per state. `S` $= 2nk$ is checked at compile time.
    ///
    /// # Errors
    /// Those of writing to `out`.
    pub fn write_csv<const N: usize, const K: usize>(&self, out: impl Write) -> io::Result<()> {
        const { assert!(S == 2 * N * K, "S must equal 2 N K") };
        let columns = state_columns(N, K);
        let rows = self
            .states
            .iter()
            .enumerate()
            .map(|(i, z)| (i as f64 * self.h, cells(&[(Some(z.as_slice()), S)])));
        write_table(out, &columns, rows)
    }
}

impl<const N: usize, const X: usize> Plan<N, X> {
    /// Writes the plan as CSV (see [`crate::output`]): the header
    /// `t,q_0,..,d1q_0,..,p0_0,..,u_0,..` ([`state_columns`]`(N, k)` with $k = X/N$, then
    /// `u_c`), then one row per node $t_i = i h$: $t_i$, the jet $x_i$, the momenta
    /// $p_i$ and the top derivative $u_i$ of step $i$ (at $t = (i + \theta) h$; empty cells in
    /// the last row, and where the plan has no momenta).
    ///
    /// # Errors
    /// Those of writing to `out`; [`io::ErrorKind::InvalidInput`] when `X` is not a multiple
    /// of `N`.
    pub fn write_csv(&self, out: impl Write) -> io::Result<()> {
        if N == 0 || !X.is_multiple_of(N) {
            return Err(invalid("a plan's jet size X must be a multiple of N"));
        }
        let mut columns = state_columns(N, X / N);
        columns.extend(top_columns(N));
        let rows = self.x.iter().enumerate().map(|(i, x)| {
            let row = cells(&[
                (Some(x.as_slice()), X),
                (self.momenta.get(i).map(|p| p.as_slice()), X),
                (self.u.get(i).map(|u| u.as_slice()), N),
            ]);
            (i as f64 * self.h, row)
        });
        write_table(out, &columns, rows)
    }
}

impl<const S: usize, const M: usize> BvpSolution<S, M> {
    /// Writes the solution as CSV (see [`crate::output`]): the header
    /// `t,q_0,..,d1q_0,..,p0_0,..,u_0,..` ([`state_columns`]`(N, K)`, then `u_c`), then one
    /// row per node $t_i = i h$: $t_i$, $z_i$ and the top derivative $u_i$ of step $i$
    /// (the last $n$ unknowns $w_i$, at $t = (i + \theta) h$; empty cells in the last row).
    /// `S` $= 2nk$ and `M` $= S + n$ are checked at compile time.
    ///
    /// # Errors
    /// Those of writing to `out`.
    pub fn write_csv<const N: usize, const K: usize>(&self, out: impl Write) -> io::Result<()> {
        const {
            assert!(
                S == 2 * N * K && M == S + N,
                "S must equal 2 N K and M = S + N"
            )
        };
        let mut columns = state_columns(N, K);
        columns.extend(top_columns(N));
        let rows = self.states.iter().enumerate().map(|(i, z)| {
            let u: Option<SVector<f64, N>> = self.top_derivative(i);
            let row = cells(&[
                (Some(z.as_slice()), S),
                (u.as_ref().map(|u| u.as_slice()), N),
            ]);
            (i as f64 * self.h, row)
        });
        write_table(out, &columns, rows)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvp::{OptimalControlProblem, PlanGuess};
    use crate::models::PlanarBarrier;
    use crate::{StepOptions, trajectory};

    const SYSTEM: PlanarBarrier = PlanarBarrier {
        tau: 0.2,
        radius: 1.0,
        mass: 1.5,
    };

    fn run() -> Trajectory<8> {
        let z0 = SVector::from([2.0, 0.1, 0.3, 1.0, -0.2, 0.05, 0.1, 1.0 / 3.0]);
        trajectory(&SYSTEM, &z0, 0.1, 12, &StepOptions::default()).unwrap()
    }

    fn plan() -> Plan<2, 4> {
        let problem = OptimalControlProblem::new(
            &SYSTEM,
            &[2.0, 0.0, 0.0, 0.5],
            &[2.5, 1.5, 0.0, 0.0],
            1.0,
            10,
        );
        // (without the smallest eigenvalue: the JSON test checks its NaN as "NaN")
        let options = crate::bvp::PlanOptions::default().with_min_eigenvalue(false);
        problem
            .with_options(options)
            .solve(PlanGuess::Spline)
            .unwrap()
    }

    /// The header, and the rows parsed back (`None` for an empty cell); every row has as
    /// many cells as the header has names.
    fn parse(csv: &[u8]) -> (Vec<String>, Vec<Vec<Option<f64>>>) {
        let text = std::str::from_utf8(csv).unwrap();
        let mut lines = text.lines();
        let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
        let rows: Vec<Vec<Option<f64>>> = lines
            .map(|line| {
                let row: Vec<Option<f64>> = line
                    .split(',')
                    .map(|cell| (!cell.is_empty()).then(|| cell.parse().unwrap()))
                    .collect();
                assert_eq!(row.len(), header.len(), "{line}");
                row
            })
            .collect();
        (header, rows)
    }

    #[test]
    fn trajectory_csv_names_every_column_and_reads_back_exactly() {
        let run = run();
        let mut csv = Vec::new();
        run.write_csv::<2, 2>(&mut csv).unwrap();
        let (header, rows) = parse(&csv);
        assert_eq!(header.len(), 1 + 8);
        assert_eq!(
            header,
            [
                "t", "q_0", "q_1", "d1q_0", "d1q_1", "p0_0", "p0_1", "p1_0", "p1_1"
            ]
        );
        assert_eq!(rows.len(), run.states.len());
        for (i, row) in rows.iter().enumerate() {
            assert_eq!(row[0], Some(run.times()[i]));
            let z: Vec<Option<f64>> = run.states[i].iter().map(|&v| Some(v)).collect();
            assert_eq!(row[1..], z[..], "row {i}");
        }
        // state i by name: column d1q_1 is q'_1
        let column = header.iter().position(|c| c == "d1q_1").unwrap();
        let state = run.state::<2, 2>(5).unwrap();
        assert_eq!(rows[5][column], Some(state.derivative(1).unwrap()[1]));
    }

    #[test]
    fn plan_csv_has_jets_momenta_and_controls_with_an_empty_last_control() {
        let plan = plan();
        let mut csv = Vec::new();
        plan.write_csv(&mut csv).unwrap();
        let (header, rows) = parse(&csv);
        assert_eq!(header.len(), 1 + 4 + 4 + 2);
        assert_eq!(&header[9..], ["u_0", "u_1"]);
        assert_eq!(rows.len(), plan.x.len());
        for (i, row) in rows.iter().enumerate() {
            assert_eq!(row[0], Some(i as f64 * plan.h));
            for c in 0..4 {
                assert_eq!(row[1 + c], Some(plan.x[i][c]), "row {i}");
                assert_eq!(row[5 + c], Some(plan.momenta[i][c]), "row {i}");
            }
            let u = plan.u.get(i).map(|u| [Some(u[0]), Some(u[1])]);
            assert_eq!(row[9..], u.unwrap_or([None, None]), "row {i}");
        }
    }

    #[test]
    fn bvp_solution_csv_adds_the_top_derivative() {
        let solution = BvpSolution::<8, 10> {
            h: 0.25,
            theta: 0.5,
            states: vec![SVector::from_fn(|r, _| r as f64 / 3.0); 3],
            unknowns: vec![SVector::from_fn(|r, _| -(r as f64) * 0.1); 2],
            cost: 1.0,
            clearance: vec![],
            iterations: 2,
            residual_norm: 0.0,
        };
        let mut csv = Vec::new();
        solution.write_csv::<2, 2>(&mut csv).unwrap();
        let (header, rows) = parse(&csv);
        assert_eq!(header.len(), 1 + 8 + 2);
        assert_eq!(rows[1][0], Some(0.25));
        assert_eq!(rows[1][2], Some(1.0 / 3.0));
        assert_eq!(rows[1][9..], [Some(-0.8), Some(-0.9)]);
        assert_eq!(rows[2][9..], [None, None]);
    }

    #[test]
    fn a_failing_writer_is_an_error() {
        struct Full;
        impl Write for Full {
            fn write(&mut self, _: &[u8]) -> io::Result<usize> {
                Err(io::Error::other("full"))
            }
            fn flush(&mut self) -> io::Result<()> {
                Ok(())
            }
        }
        assert!(run().write_csv::<2, 2>(Full).is_err());
    }

    /// JSON round trips are exact: serde_json writes the shortest round-trip form, and its
    /// `float_roundtrip` feature parses it back exactly (without it the last bit can differ).
    #[cfg(feature = "serde")]
    #[test]
    fn results_round_trip_through_json() {
        let run = run();
        let json = serde_json::to_string(&run).unwrap();
        assert_eq!(serde_json::from_str::<Trajectory<8>>(&json).unwrap(), run);
        let plan = plan();
        let json = serde_json::to_string(&plan).unwrap();
        let back = serde_json::from_str::<Plan<2, 4>>(&json).unwrap();
        // the minimum eigenvalue is NaN when not asked for: written as "NaN", read back as NaN
        assert!(plan.certificate.min_reduced_hessian_eig.is_nan());
        assert!(
            json.contains("\"min_reduced_hessian_eig\":\"NaN\""),
            "{json}"
        );
        assert!(back.certificate.min_reduced_hessian_eig.is_nan());
        let finite = |mut plan: Plan<2, 4>| {
            plan.certificate.min_reduced_hessian_eig = 0.25;
            plan
        };
        assert_eq!(finite(back), finite(plan.clone()));
        let plan = finite(plan);
        let json = serde_json::to_string(&plan).unwrap();
        assert_eq!(serde_json::from_str::<Plan<2, 4>>(&json).unwrap(), plan);
        let state = run.state::<2, 2>(3).unwrap();
        let json = serde_json::to_string(&state).unwrap();
        assert!(json.starts_with("{\"x\":[["), "{json}");
        assert_eq!(
            serde_json::from_str::<crate::State<2, 2>>(&json).unwrap(),
            state
        );
        // a state with a missing or an extra block is rejected
        let short = r#"{"x":[[1.0,2.0]],"p":[[1.0,2.0],[3.0,4.0]]}"#;
        assert!(serde_json::from_str::<crate::State<2, 2>>(short).is_err());
        let long = r#"{"x":[[1,2],[3,4],[5,6]],"p":[[1,2],[3,4]]}"#;
        assert!(serde_json::from_str::<crate::State<2, 2>>(long).is_err());
        let jet = crate::Jet::<2, 2>::new(&[[1.0, 2.0], [3.0, 4.0], [5.0, 6.0], [7.0, 8.0]]);
        let jet = jet.unwrap();
        let json = serde_json::to_string(&jet).unwrap();
        assert_eq!(
            serde_json::from_str::<crate::Jet<2, 2>>(&json).unwrap(),
            jet
        );
        // errors serialize (not deserialize: they hold static strings)
        let error = serde_json::to_value(crate::Error::NonFinite {
            iteration: 3,
            location: "here",
        })
        .unwrap();
        assert_eq!(error["NonFinite"]["iteration"], 3);
    }
}
