//! The speed report at quick size: it runs, prints its header and tables, and its
//! `work-precision 1e-8: best=<method> <t> us, DOP853 <t> us, ratio <r>` line parses with
//! r = best / DOP853 within the rounding of the printed figures; the planner's tables and its
//! `ratios: ...` line are there, with one ratio per race; the compile-time table is there. No
//! timing is asserted; the `sphere cubic ...` lines are there, one pair per resolution; the
//! receding horizon's `kick=... mode=...` lines are there, every re-plan certified.

use retract_validation::planner_speed::PlannerSpeed;
use retract_validation::report::{self, Size, utc_date};
use retract_validation::work_precision::time_at_error;

/// (method, best, DOP853, ratio) from the line.
fn parse_line(line: &str) -> Option<(&str, f64, f64, f64)> {
    let rest = line.strip_prefix("work-precision 1e-8: best=")?;
    let (best, rest) = rest.split_once(" us, DOP853 ")?;
    let (method, best) = best.rsplit_once(' ')?;
    let (dop, ratio) = rest.split_once(" us, ratio ")?;
    Some((
        method,
        best.parse().ok()?,
        dop.parse().ok()?,
        ratio.parse().ok()?,
    ))
}

#[test]
fn quick_report_prints_the_work_precision_line() {
    let mut out = Vec::new();
    let summary = report::run(&Size::quick(), &mut out).expect("the quick report runs");
    let text = String::from_utf8(out).expect("utf-8");
    assert!(
        text.starts_with("# retract speed report, "),
        "header:\n{text}"
    );
    for table in [
        "| one step | time | vs generated reduced |",
        "| 400-step run | time |",
        "| guard | time |",
        "| method | steps / tol | final error | wall time |",
        "| method | at 1e-8 |",
        "| method | step size / tol | steps | wall time |",
        "| N | 100 | 200 | 400 | 800 | 1600 | 3200 |",
        "| N = 400 | Newton iterations | time | vs `solve_reduced` |",
        "| N = 400 | optimizer | root finder | ratio | best / best | iterations (optimizer, root finder) | \
         cost difference |",
        "| N | cost error | estimate | $p(0)$ error | iterations ($N$, $2N$, $4N$) | time |",
        "| n | barrier terms | lines | expansion |",
    ] {
        assert!(text.contains(table), "missing `{table}` in:\n{text}");
    }
    let lines: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("work-precision 1e-8: "))
        .collect();
    assert_eq!(lines.len(), 1, "one work-precision line in:\n{text}");
    let (method, best, dop, ratio) =
        parse_line(lines[0]).unwrap_or_else(|| panic!("unparsed: {}", lines[0]));
    assert!(!method.is_empty() && best > 0.0 && dop > 0.0);
    // the printed times are rounded to 0.05 us, the ratio to 0.005
    let (low, high) = ((best - 0.05) / (dop + 0.05), (best + 0.05) / (dop - 0.05));
    assert!(
        ratio >= low - 0.005 && ratio <= high + 0.005,
        "ratio {ratio} is not {best} / {dop}"
    );
    let (label, t) = summary.at_target.best.expect("a best method");
    assert_eq!(label, method);
    assert!((t * 1e6 - best).abs() <= 0.05 + 1e-9);
    assert!(
        text.lines()
            .any(|l| l.starts_with("work-precision 1e-8 without the guard: ")),
        "{text}"
    );
    planner_lines(&text, &summary.planner);
    step_ratio_line(&text);
    batch_lines(&text);
    sphere_lines(&text);
    receding_horizon_lines(&text);
}

/// The receding horizon's lines: one `kick=<k> mode=<m> ...` line per kick (2, 8) and mode
/// (rti1, rti2, full), each held upright (its largest deviation below pi) without a failed
/// re-plan and settled (a finite settling time), a positive median time; one `feedback` line
/// per kick and real-time mode.
fn receding_horizon_lines(text: &str) {
    let field = |line: &str, key: &str| -> f64 {
        let value = (line.split(' '))
            .find_map(|w| w.strip_prefix(key))
            .unwrap_or_else(|| panic!("no `{key}` in `{line}`"));
        value
            .parse()
            .unwrap_or_else(|_| panic!("`{key}{value}` in `{line}`"))
    };
    for kick in ["2", "8"] {
        for mode in ["rti1", "rti2", "full"] {
            let prefix = format!("kick={kick} mode={mode} ");
            let lines: Vec<&str> = text.lines().filter(|l| l.starts_with(&prefix)).collect();
            assert_eq!(lines.len(), 1, "one `{prefix}` line in:\n{text}");
            let line = lines[0];
            assert_eq!(field(line, "failures="), 0.0, "{line}");
            assert!(field(line, "settle_s=").is_finite(), "{line}");
            assert!(field(line, "median_us=") > 0.0, "{line}");
            // held: the pendulum never swings past the horizontal of the other side
            let deviation = field(line, "max_dev=");
            assert!(
                deviation > 0.0 && deviation < std::f64::consts::PI,
                "{line}"
            );
            if mode != "full" {
                let feedback = format!("feedback kick={kick} mode={mode} median_us=");
                assert!(text.lines().any(|l| l.starts_with(&feedback)), "{feedback}");
            }
        }
    }
}

/// The lines `sphere cubic error=<e> time_us=<t> method=<retract|decasteljau>`: one pair per
/// resolution (retract, then de Casteljau), positive figures, retract's error falling with
/// the resolution and de Casteljau's staying (it is another curve than the cubic).
fn sphere_lines(text: &str) {
    let rows: Vec<(f64, f64, &str)> = (text.lines())
        .filter_map(|l| l.strip_prefix("sphere cubic error="))
        .map(|rest| {
            let (e, rest) = rest.split_once(" time_us=").expect("time_us");
            let (t, method) = rest.split_once(" method=").expect("method");
            let parse = |v: &str| v.parse::<f64>().expect("a number");
            (parse(e), parse(t), method)
        })
        .collect();
    let resolutions = retract_validation::sphere_cubic::RESOLUTIONS.len();
    assert_eq!(
        rows.len(),
        2 * resolutions,
        "sphere cubic lines in:\n{text}"
    );
    for (i, &(e, t, method)) in rows.iter().enumerate() {
        assert_eq!(method, ["retract", "decasteljau"][i % 2], "{rows:?}");
        assert!(e > 0.0 && e.is_finite() && t > 0.0, "{rows:?}");
    }
    let errors = |m: usize| {
        rows.iter()
            .skip(m)
            .step_by(2)
            .map(|r| r.0)
            .collect::<Vec<_>>()
    };
    let (retract, casteljau) = (errors(0), errors(1));
    assert!(retract.windows(2).all(|w| w[1] < w[0]), "{rows:?}");
    assert!(
        casteljau
            .iter()
            .all(|e| (e - casteljau[0]).abs() <= 1e-3 * casteljau[0]),
        "{rows:?}"
    );
    assert!(
        text.contains("| N | retract error | retract time | extrapolated error, curve (nodes) |"),
        "{text}"
    );
}

/// The batch lines: for each batch, `batch <name> threads=<t> plans_per_s=<p> scaling=<s>`
/// for t = 1, 2, ... in turn, with positive figures and scaling 1 at one thread.
/// The line `step ratio generated/hand-written: <r> (guard, no compensation), <r2>
/// (compensated)`: once, with positive ratios.
fn step_ratio_line(text: &str) {
    let lines: Vec<&str> = (text.lines())
        .filter_map(|l| l.strip_prefix("step ratio generated/hand-written: "))
        .collect();
    assert_eq!(lines.len(), 1, "one step-ratio line in:\n{text}");
    let (r, rest) = lines[0]
        .split_once(" (guard, no compensation), ")
        .unwrap_or_else(|| panic!("unparsed: {}", lines[0]));
    let r2 = rest
        .strip_suffix(" (compensated)")
        .unwrap_or_else(|| panic!("unparsed: {}", lines[0]));
    let (r, r2): (f64, f64) = (r.parse().expect("r"), r2.parse().expect("r2"));
    assert!(r > 0.0 && r2 > 0.0, "{}", lines[0]);
}

/// The lines `batch <name> threads=<t> plans_per_s=<p> scaling=<s>`: one per thread count
/// from 1, positive figures, the first scaling 1.
fn batch_lines(text: &str) {
    for name in ["one-disc", "swing-up"] {
        let prefix = format!("batch {name} threads=");
        let rows: Vec<(usize, f64, f64)> = (text.lines())
            .filter_map(|l| l.strip_prefix(&prefix))
            .map(|rest| {
                let (t, rest) = rest.split_once(" plans_per_s=").expect("plans_per_s");
                let (p, s) = rest.split_once(" scaling=").expect("scaling");
                let parse = |v: &str| v.parse::<f64>().expect("a number");
                (t.parse().expect("a thread count"), parse(p), parse(s))
            })
            .collect();
        assert!(!rows.is_empty(), "no `{prefix}` lines in:\n{text}");
        for (i, &(t, p, s)) in rows.iter().enumerate() {
            assert_eq!(t, i + 1);
            assert!(p > 0.0 && s > 0.0, "{name}: {rows:?}");
        }
        assert_eq!(rows[0].2, 1.0);
    }
}

/// The planner's lines: one `ratios: ` line naming every race, the races as solved (both
/// solvers to the same cost), every time measured.
fn planner_lines(text: &str, planner: &PlannerSpeed) {
    let lines: Vec<&str> = text.lines().filter(|l| l.starts_with("ratios: ")).collect();
    assert_eq!(lines.len(), 1, "one ratios line in:\n{text}");
    let cases: Vec<&str> = planner.races.iter().map(|r| r.case).collect();
    assert_eq!(
        cases,
        ["one-disc cold", "one-disc warm", "se2 cold", "se2 warm"]
    );
    for race in &planner.races {
        let printed = format!("{} {:.2}x", race.case, race.ratio());
        assert!(lines[0].contains(&printed), "`{printed}` in {}", lines[0]);
        assert!(race.cost_difference() < 1e-8, "{race:?}");
    }
    let size = Size::quick();
    let solves = planner
        .against_n
        .iter()
        .chain(&planner.at_400)
        .map(|s| (s, size.planner_rounds))
        .chain(
            planner
                .races
                .iter()
                .flat_map(|r| [&r.optimizer, &r.root])
                .map(|s| (s, size.race_rounds)),
        );
    for (solve, rounds) in solves {
        assert_eq!(solve.samples.0.len(), rounds, "{solve:?}");
        assert!(solve.samples.best() > 0.0, "{solve:?}");
    }
    assert_eq!(planner.extrapolation.len(), 3);
    for e in &planner.extrapolation {
        assert!(e.cost_error < 1e-8 && e.samples.best() > 0.0, "{e:?}");
    }
}

#[test]
fn line_parser_reads_the_readme_example() {
    let line =
        "work-precision 1e-8: best=splitting, BM SRKN14a 14.5 us, DOP853 16.6 us, ratio 0.87";
    assert_eq!(
        parse_line(line),
        Some(("splitting, BM SRKN14a", 14.5, 16.6, 0.87))
    );
}

#[test]
fn utc_dates() {
    use std::time::{Duration, UNIX_EPOCH};
    assert_eq!(utc_date(UNIX_EPOCH), "1970-01-01");
    // 2000-02-29 and 2026-11-23, midday
    let day = |d: u64| UNIX_EPOCH + Duration::from_secs(d * 86_400 + 43_200);
    assert_eq!(utc_date(day(11_016)), "2000-02-29");
    assert_eq!(utc_date(day(20_780)), "2026-11-23");
}

#[test]
fn interpolation_between_sweep_points() {
    // error 1e-6 at 1 s, 1e-10 at 100 s: 1e-8 halfway on the log scale, at 10 s
    let t = time_at_error(&[(1.0, 1e-6), (100.0, 1e-10)], 1e-8).expect("bracketed");
    assert!((t - 10.0).abs() < 1e-9);
    assert_eq!(time_at_error(&[(1.0, 1e-6), (2.0, 1e-7)], 1e-8), None);
}

#[test]
fn the_report_replaces_only_its_marked_block() {
    let document = format!(
        "# Title\n\nprose above\n\n{}\nold report\nold line\n{}\n\nprose below\n",
        report::BLOCK_BEGIN,
        report::BLOCK_END
    );
    let updated = report::replace_block(&document, "new report\n").expect("markers found");
    assert_eq!(
        updated,
        format!(
            "# Title\n\nprose above\n\n{}\n\nnew report\n\n{}\n\nprose below\n",
            report::BLOCK_BEGIN,
            report::BLOCK_END
        )
    );
    // Written twice, the block is the same (the markers stay, nothing accumulates).
    let again = report::replace_block(&updated, "new report\n").expect("markers found");
    assert_eq!(again, updated);
    // Without both markers in order, nothing is written.
    assert!(report::replace_block("no markers", "x").is_none());
    let reversed = format!("{}\n{}\n", report::BLOCK_END, report::BLOCK_BEGIN);
    assert!(report::replace_block(&reversed, "x").is_none());
    assert_eq!(
        report::demoted("# report\ntext # not a heading\n## part"),
        "### report\ntext # not a heading\n#### part"
    );
    let path = std::env::temp_dir().join(format!("retract-report-{}.md", std::process::id()));
    std::fs::write(&path, "no markers").expect("temp file");
    let error = report::write_block(&path, "x").expect_err("refused without markers");
    assert!(error.to_string().contains("report:begin"), "{error}");
    assert_eq!(std::fs::read_to_string(&path).expect("read"), "no markers");
    let _ = std::fs::remove_file(&path);
}

#[test]
fn the_benchmarks_page_holds_the_report_block() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/benchmarks.md");
    let page = std::fs::read_to_string(&path).expect("docs/benchmarks.md");
    assert!(
        report::replace_block(&page, "x").is_some(),
        "docs/benchmarks.md must hold the report's markers"
    );
}
