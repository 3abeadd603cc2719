//! The build script that embeds the README's figures in the crate documentation
//! (`build.rs`, included here by path).

#[allow(dead_code)] // its `main` is the build script's
#[path = "../../build.rs"]
mod build_script;

use build_script::{base64, embed_figures};

/// RFC 4648's test vectors.
#[test]
fn base64_matches_the_standard() {
    for (input, expected) in [
        ("", ""),
        ("f", "Zg=="),
        ("fo", "Zm8="),
        ("foo", "Zm9v"),
        ("foob", "Zm9vYg=="),
        ("fooba", "Zm9vYmE="),
        ("foobar", "Zm9vYmFy"),
    ] {
        assert_eq!(base64(input.as_bytes()), expected, "{input}");
    }
}

/// A figure under docs/ becomes a data URI; other links, missing files and a lone `![` stay.
#[test]
fn svg_figures_become_data_uris() {
    let text = "a ![plot \"1\"](docs/a.svg) b ![x](docs/missing.svg) c ![y](other.png) d ![ e";
    let out = embed_figures(text, |path| (path == "docs/a.svg").then(|| b"foo".to_vec()));
    assert_eq!(
        out,
        "a <img alt=\"plot &quot;1&quot;\" src=\"data:image/svg+xml;base64,Zm9v\"> b \
         ![x](docs/missing.svg) c ![y](other.png) d ![ e"
    );
}
