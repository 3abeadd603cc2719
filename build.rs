//! The crate documentation is the README with its figures embedded: every image
//! `![alt](docs/name.svg)` becomes `<img alt="alt" src="data:image/svg+xml;base64,...">`, so the
//! figures show on docs.rs (whose pages do not serve the repository's files) and in a local
//! `cargo doc`. The result is `$OUT_DIR/README.md`, included by `src/lib.rs`. The README itself
//! is unchanged (its relative links work where the repository is browsed).

use std::{env, fs, path::Path};

fn main() {
    println!("cargo:rerun-if-changed=README.md");
    println!("cargo:rerun-if-changed=docs");
    let readme = fs::read_to_string("README.md").expect("README.md next to Cargo.toml");
    let embedded = embed_figures(&readme, |path| {
        println!("cargo:rerun-if-changed={path}");
        fs::read(path).ok()
    });
    let out = env::var("OUT_DIR").expect("cargo sets OUT_DIR");
    fs::write(Path::new(&out).join("README.md"), embedded).expect("OUT_DIR is writable");
}

/// `text` with every `![alt](docs/*.svg)` whose file `read` finds replaced by an `<img>` with
/// the file as a data URI (a figure whose file is missing keeps its link).
pub fn embed_figures(text: &str, mut read: impl FnMut(&str) -> Option<Vec<u8>>) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(start) = rest.find("![") {
        out.push_str(&rest[..start]);
        let tail = &rest[start..];
        let figure = tail.find("](").and_then(|close| {
            let end = close + tail[close..].find(')')?;
            let (alt, path) = (&tail[2..close], &tail[close + 2..end]);
            let svg = (path.starts_with("docs/") && path.ends_with(".svg"))
                .then(|| read(path))
                .flatten()?;
            let img = format!(
                "<img alt=\"{}\" src=\"data:image/svg+xml;base64,{}\">",
                alt.replace('"', "&quot;"),
                base64(&svg)
            );
            Some((img, end + 1))
        });
        match figure {
            Some((img, length)) => {
                out.push_str(&img);
                rest = &tail[length..];
            }
            None => {
                out.push_str("![");
                rest = &tail[2..];
            }
        }
    }
    out.push_str(rest);
    out
}

/// Standard base64 (RFC 4648, with padding).
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for (i, shift) in [18, 12, 6, 0].into_iter().enumerate() {
            if i <= chunk.len() {
                out.push(char::from(ALPHABET[((n >> shift) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}
