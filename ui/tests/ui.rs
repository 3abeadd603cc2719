//! Compile-time behaviour of the attributes: every mistake in `tests/ui/fail`, sorted by topic
//! (`signature`, `syntax`, `expressions`, `helpers`, `outputs`, `maps`, `manifolds`,
//! `legendre`, `mechanical`), is an error at its span with the message in the `.stderr` beside
//! it; every file in `tests/ui/pass` compiles and runs. Refresh the messages with
//! `TRYBUILD=overwrite`.

#[test]
fn ui() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/fail/*/*.rs");
    t.pass("tests/ui/pass/*.rs");
}
