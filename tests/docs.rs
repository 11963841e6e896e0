//! The documentation holds together: every relative link and image in the README and the book
//! (`docs/`) names a file that exists and, with `#anchor`, a heading of that file; every
//! chapter is in the book's `SUMMARY.md`; the README stays short; the generated field
//! reference of the vector format is what the code writes.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The markdown text outside fenced code blocks and inline code spans.
fn prose(text: &str) -> String {
    let mut out = String::new();
    let mut fence = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fence = !fence;
            out.push('\n');
            continue;
        }
        if fence {
            out.push('\n');
            continue;
        }
        // drop inline code spans
        let mut in_code = false;
        for c in line.chars() {
            if c == '`' {
                in_code = !in_code;
            } else if !in_code {
                out.push(c);
            }
        }
        out.push('\n');
    }
    out
}

/// The anchors of a markdown file's headings (mdBook's and GitHub's rule: lower case,
/// alphanumerics, `-` and `_` kept, whitespace to `-`, the rest dropped; repeats get `-1`, `-2`).
fn anchors(text: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut fence = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fence = !fence;
        }
        if fence || !line.starts_with('#') {
            continue;
        }
        let title = line.trim_start_matches('#').trim();
        let base: String = title
            .chars()
            .filter_map(|c| {
                if c.is_alphanumeric() || c == '_' || c == '-' {
                    Some(c.to_lowercase().next().unwrap_or(c))
                } else if c.is_whitespace() {
                    Some('-')
                } else {
                    None
                }
            })
            .collect();
        let mut id = base.clone();
        let mut k = 1;
        while seen.contains(&id) {
            id = format!("{base}-{k}");
            k += 1;
        }
        seen.insert(id);
    }
    seen
}

/// Every `[text](target)` / `![alt](target)` target in the prose of `text`.
fn links(text: &str) -> Vec<String> {
    let p = prose(text);
    let mut out = Vec::new();
    let b = p.as_bytes();
    let mut i = 0;
    while i + 1 < b.len() {
        if b[i] == b']' && b[i + 1] == b'(' {
            if let Some(end) = p[i + 2..].find(')') {
                let t = p[i + 2..i + 2 + end].trim();
                // a title after the target: [x](file "title")
                let t = t.split_whitespace().next().unwrap_or("");
                out.push(t.to_string());
                i += 2 + end;
                continue;
            }
        }
        i += 1;
    }
    out
}

fn markdown_files() -> Vec<PathBuf> {
    let mut v = vec![root().join("README.md")];
    for e in std::fs::read_dir(root().join("docs")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "md") {
            v.push(p);
        }
    }
    v.sort();
    v
}

fn check_link(from: &Path, target: &str) -> Result<(), String> {
    if target.is_empty()
        || target.starts_with("http://")
        || target.starts_with("https://")
        || target.starts_with("mailto:")
    {
        return Ok(());
    }
    let (path, anchor) = match target.split_once('#') {
        Some((p, a)) => (p, Some(a)),
        None => (target, None),
    };
    let file = if path.is_empty() { from.to_path_buf() } else { from.parent().unwrap().join(path) };
    if !file.exists() {
        return Err(format!("{}: link to {target}: no such file", from.display()));
    }
    if let Some(a) = anchor {
        if file.extension().is_some_and(|x| x == "md") {
            let text = std::fs::read_to_string(&file).unwrap();
            if !anchors(&text).contains(a) {
                return Err(format!("{}: link to {target}: no heading with anchor #{a}", from.display()));
            }
        }
    }
    Ok(())
}

#[test]
fn every_relative_link_and_anchor_resolves() {
    let mut bad = Vec::new();
    let mut n = 0;
    for f in markdown_files() {
        let text = std::fs::read_to_string(&f).unwrap();
        for t in links(&text) {
            n += 1;
            if let Err(e) = check_link(&f, &t) {
                bad.push(e);
            }
        }
    }
    assert!(n > 100, "only {n} links found: the link scanner is broken");
    assert!(bad.is_empty(), "{} broken links:\n{}", bad.len(), bad.join("\n"));
}

#[test]
fn the_link_checker_finds_broken_links() {
    let f = root().join("README.md");
    assert!(check_link(&f, "docs/no-such-chapter.md").is_err());
    assert!(check_link(&f, "docs/install.md#no-such-heading").is_err());
    assert!(check_link(&f, "docs/install.md").is_ok());
    assert_eq!(
        links("see [a](x.md) and `[b](y.md)` and ![c](img/z.png \"t\")\n```\n[d](w.md)\n```\n"),
        ["x.md", "img/z.png"]
    );
    let a = anchors("# Speed (`raypipe speed`)\n## A b\n## A b\n");
    assert!(a.contains("speed-raypipe-speed") && a.contains("a-b") && a.contains("a-b-1"), "{a:?}");
}

#[test]
fn every_chapter_is_in_the_book() {
    let summary = std::fs::read_to_string(root().join("docs/SUMMARY.md")).unwrap();
    let listed: BTreeSet<String> = links(&summary).into_iter().collect();
    for f in markdown_files() {
        let name = f.file_name().unwrap().to_str().unwrap().to_string();
        if f.parent().unwrap().ends_with("docs") && name != "SUMMARY.md" {
            assert!(listed.contains(&name), "docs/{name} is not in docs/SUMMARY.md");
        }
    }
    for l in &listed {
        assert!(root().join("docs").join(l).exists(), "SUMMARY.md lists {l}, which does not exist");
    }
}

#[test]
fn the_readme_is_short() {
    let n = std::fs::read_to_string(root().join("README.md")).unwrap().lines().count();
    assert!(n <= 300, "README.md has {n} lines; the front door is at most 300 (details go to docs/)");
}

/// `docs/vector-fields.md` is what the generator's manifests say
/// (`RAYPIPE_BLESS_DOCS=1 cargo test --release --test docs` rewrites it).
#[test]
fn the_vector_field_reference_is_generated() {
    let want = raypipe::field_reference::field_reference().unwrap();
    let path = root().join("docs/vector-fields.md");
    if std::env::var_os("RAYPIPE_BLESS_DOCS").is_some() {
        std::fs::write(&path, &want).unwrap();
    }
    let have = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(have == want, "docs/vector-fields.md is stale: RAYPIPE_BLESS_DOCS=1 cargo test --release --test docs");
}

/// `docs/coverage-model.md` is what the coverage model says
/// (`RAYPIPE_BLESS_DOCS=1 cargo test --release --test docs` rewrites it).
#[test]
fn the_coverage_model_reference_is_generated() {
    let want = raypipe::cover_reference::coverage_reference().unwrap();
    let path = root().join("docs/coverage-model.md");
    if std::env::var_os("RAYPIPE_BLESS_DOCS").is_some() {
        std::fs::write(&path, &want).unwrap();
    }
    let have = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(have == want, "docs/coverage-model.md is stale: RAYPIPE_BLESS_DOCS=1 cargo test --release --test docs");
}

/// Text in prose that a markdown renderer reads as an HTML tag (`<x>`, `</x>`, `<x ...`), which
/// mdBook warns about when it is left unclosed: the book's pages use none.
fn raw_tags(text: &str) -> Vec<String> {
    let p = prose(text);
    let b = p.as_bytes();
    let mut out = Vec::new();
    for (i, &c) in b.iter().enumerate() {
        if c != b'<' {
            continue;
        }
        let j = if b.get(i + 1) == Some(&b'/') { i + 2 } else { i + 1 };
        if b.get(j).is_some_and(|c| c.is_ascii_alphabetic()) {
            let end = p[i..].find(['\n', '>']).map_or(p.len(), |k| i + k + 1);
            out.push(p[i..end.min(i + 40)].to_string());
        }
    }
    out
}

#[test]
fn no_page_holds_a_raw_html_tag() {
    assert_eq!(raw_tags("a q<I>.<F> b `<x>` c <= d"), ["<I>", "<F>"]);
    let mut bad = Vec::new();
    for f in markdown_files() {
        for t in raw_tags(&std::fs::read_to_string(&f).unwrap()) {
            bad.push(format!("{}: {t}", f.display()));
        }
    }
    assert!(bad.is_empty(), "tag-like text outside code:\n{}", bad.join("\n"));
}
