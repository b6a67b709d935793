//! The house rules, checked: the workspace's crates sit in layers with every dependency pointing
//! down, and inside every crate no module imports a module that imports it back (directly or
//! round a circle). Run with `--nocapture` to print the module graph.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, bottom first. A crate may depend (normal or build dependency) only on crates of
/// lower layers; dev-dependencies are free (tests sit above everything).
const LAYERS: &[&[&str]] = &[
    &["specconv-shim-build", "specconv-atomic-file"],
    &[
        "specconv-colour",
        "specconv-exr",
        "oiio-sys",
        "ocio-sys",
        "specconv-figures",
    ],
    &[
        "specconv-spectral",
        "specconv-oiio",
        "specconv-ocio",
        "specconv-icc",
    ],
    &[
        "specconv-evaluation",
        "specconv-farm",
        "specconv-description",
    ],
    // The job, under the description of what it does.
    &["specconv-pipeline"],
    &["specconv-conversion"],
    // An asset (a USD stage) over the conversion: its textures decided by their materials; the
    // command line's flags, from the conversion's definitions and one table of the commands'.
    &["specconv-asset", "specconv-flags"],
    // The convert command and the ground of every command (printing, errors, exit statuses);
    // the Python package, the other front-end.
    &[
        "specconv-convert-cmd",
        "specconv-python",
        "specconv-testkit",
    ],
    // The farm command, over the convert command its tasks run.
    &["specconv-farm-cmd"],
    // The command line: dispatch and the other commands.
    &["specconv-cli"],
    // The program, and the developers' own tools over everything (never shipped).
    &["specconv", "specconv-dev"],
];

/// The science knows nothing of images, files, threads or FFI.
const SCIENCE: &[&str] = &[
    "specconv-colour",
    "specconv-spectral",
    "specconv-evaluation",
];
const NOT_FOR_SCIENCE: &[&str] = &[
    "specconv-exr",
    "specconv-conversion",
    "specconv-oiio",
    "specconv-ocio",
    "oiio-sys",
    "ocio-sys",
    "rayon",
    "exr",
    "image",
];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// docs/architecture.md draws the layers (`layer N: a, b — what`, top first, the crates
/// without `specconv-`): the drawing is this list, so that the two cannot drift.
#[test]
fn the_architecture_s_layers_are_the_checked_ones() {
    let doc = std::fs::read_to_string(root().join("docs/architecture.md")).unwrap();
    let mut drawn: Vec<(usize, Vec<String>)> = doc
        .lines()
        .filter_map(|l| {
            let (n, rest) = l.trim().strip_prefix("layer ")?.split_once(':')?;
            let crates = rest.split(" — ").next()?;
            let names = crates.split(',').map(|c| c.trim().to_owned()).collect();
            Some((n.parse().ok()?, names))
        })
        .collect();
    drawn.sort();
    let short = |c: &str| c.strip_prefix("specconv-").unwrap_or(c).to_owned();
    let listed: Vec<(usize, Vec<String>)> = LAYERS
        .iter()
        .enumerate()
        .map(|(k, l)| (k, l.iter().map(|c| short(c)).collect()))
        .collect();
    assert_eq!(drawn, listed);
}

fn layer(name: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&name))
}

/// The manifests of the workspace: the root's and every member's.
fn manifests() -> Vec<PathBuf> {
    let mut out = vec![root().join("Cargo.toml"), root().join("python/Cargo.toml")];
    for dir in ["crates", "ffi"] {
        let mut members: Vec<_> = std::fs::read_dir(root().join(dir))
            .unwrap()
            .map(|e| e.unwrap().path().join("Cargo.toml"))
            .filter(|p| p.is_file())
            .collect();
        members.sort();
        out.extend(members);
    }
    out
}

/// The package name and its normal and build dependencies, from a manifest (the few lines of
/// TOML this needs: `[package] name = "…"` and the keys of `[dependencies]`,
/// `[build-dependencies]`).
fn dependencies(manifest: &Path) -> (String, Vec<String>) {
    let text = std::fs::read_to_string(manifest).unwrap();
    let (mut name, mut deps, mut section) = (String::new(), Vec::new(), String::new());
    for line in text.lines().map(str::trim) {
        if line.starts_with('[') {
            section = line.to_string();
        } else if section == "[package]" && line.starts_with("name") {
            name = line.split('"').nth(1).unwrap().to_string();
        } else if (section == "[dependencies]" || section == "[build-dependencies]")
            && !line.is_empty()
            && !line.starts_with('#')
        {
            let key = line.split(['=', '.', ' ']).next().unwrap();
            deps.push(key.to_string());
        }
    }
    (name, deps)
}

/// The crates that wrap C and C++ (OpenImageIO, OpenColorIO, Little CMS) and build their shims.
const FFI: &[&str] = &[
    "specconv-oiio",
    "specconv-ocio",
    "specconv-icc",
    "oiio-sys",
    "ocio-sys",
    "specconv-shim-build",
];

/// The front-ends, by manifest and sources: the command line's three crates and the Python
/// package.
const FRONT_ENDS: &[(&str, &str, &str)] = &[
    ("specconv-cli", "crates/cli/Cargo.toml", "crates/cli/src"),
    (
        "specconv-convert-cmd",
        "crates/convert-cmd/Cargo.toml",
        "crates/convert-cmd/src",
    ),
    (
        "specconv-farm-cmd",
        "crates/farm-cmd/Cargo.toml",
        "crates/farm-cmd/src",
    ),
    ("specconv-python", "python/Cargo.toml", "python/src"),
];

/// The `.rs` files under `dir`.
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut dirs = vec![dir.to_path_buf()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|e| e == "rs") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// The command line and the Python package reach the C and C++ libraries, and the
/// conversion's rules, only through the conversion library, so that every front-end gets the
/// same rules: neither depends on an FFI crate nor names one in its code (the facade's API
/// holds none of their types). The Python package may use the pure-Rust crates beneath the
/// facade (the science for its array functions, the spectral EXR crate for reading and
/// writing files, atomic files), as the CLI does. Neither spells a `specconv*` attribute
/// (provenance is the library's). One dependency is for the build alone: the Python package's
/// build script copies the OpenImageIO shim that oiio-sys built into the package (cargo tells
/// only a direct dependent where, `DEP_SPECCONV_OIIO_SHIM`, and shim-build copies it); its code
/// names no FFI crate.
/// The command line reaches file formats only through the library (which checks names by them);
/// the Python package reads and writes spectral files itself, with the same crate.
#[test]
fn the_command_line_reaches_file_formats_through_the_library() {
    let command_line = FRONT_ENDS
        .iter()
        .filter(|(package, ..)| *package != "specconv-python");
    for &(package, manifest, _) in command_line {
        let (_, deps) = dependencies(&root().join(manifest));
        for format in ["specconv-exr", "exr", "image"] {
            assert!(
                !deps.iter().any(|d| d == format),
                "{package} depends on {format}: reach it through specconv-conversion"
            );
        }
    }
}

#[test]
fn the_front_ends_reach_the_libraries_only_through_the_conversion_library() {
    const FOR_THE_BUILD_ONLY: &[(&str, &str)] = &[
        ("specconv-python", "oiio-sys"),
        ("specconv-python", "specconv-shim-build"),
    ];
    for &(package, manifest, src) in FRONT_ENDS {
        let (name, deps) = dependencies(&root().join(manifest));
        assert_eq!(name, package);
        for below in FFI {
            if FOR_THE_BUILD_ONLY.contains(&(package, below)) {
                continue;
            }
            assert!(
                !deps.iter().any(|d| d == below),
                "{package} depends on {below}: reach it through specconv-conversion"
            );
        }
        assert!(
            deps.iter().any(|d| d == "specconv-conversion"),
            "{package}: {deps:?}"
        );
        for p in sources(&root().join(src)) {
            let text = std::fs::read_to_string(&p).unwrap();
            let code = code(&text);
            for ffi in FFI {
                let path = ffi.replace('-', "_");
                assert!(
                    !code.contains(&format!("{path}::")) && !code.contains(&format!("use {path}")),
                    "{} names {ffi}: reach it through specconv_conversion",
                    p.display()
                );
            }
            for (i, _) in text.match_indices("\"specconv") {
                let next = text[i + 9..].chars().next().unwrap_or(' ');
                assert!(
                    !next.is_ascii_uppercase(),
                    "{} spells a specconv attribute: use specconv_conversion::provenance",
                    p.display()
                );
            }
        }
    }
}

/// The facade hands out no FFI crate: no `pub use` of one anywhere in its sources (its own
/// types wrap what front-ends need, `ColourConfig`, `describe`, `ImageError`).
#[test]
fn the_conversion_library_reexports_no_ffi_crate() {
    for p in sources(&root().join("crates/conversion/src")) {
        let code = code(&std::fs::read_to_string(&p).unwrap());
        for ffi in FFI {
            let path = ffi.replace('-', "_");
            assert!(
                !code.contains(&format!("pub use {path}")),
                "{} re-exports {ffi}: wrap what a front-end needs in a type of the facade",
                p.display()
            );
        }
    }
}

/// The checks above see what they look for.
#[test]
fn the_front_end_checks_see_ffi_names() {
    let code = code("use specconv_oiio::ImageReader; // specconv_ocio:: in a comment\n");
    assert!(code.contains("specconv_oiio::"));
    assert!(!code.contains("specconv_ocio::"));
    let (name, deps) = dependencies(&root().join("python/Cargo.toml"));
    assert_eq!(name, "specconv-python");
    assert!(deps.iter().any(|d| d == "pyo3"), "{deps:?}");
}

#[test]
fn crates_depend_only_on_lower_layers() {
    let mut wrong = Vec::new();
    for manifest in manifests() {
        let (name, deps) = dependencies(&manifest);
        let Some(own) = layer(&name) else {
            wrong.push(format!(
                "{name} ({}) has no layer in LAYERS",
                manifest.display()
            ));
            continue;
        };
        for dep in deps {
            if let Some(theirs) = layer(&dep) {
                if theirs >= own {
                    wrong.push(format!(
                        "{name} (layer {own}) depends on {dep} (layer {theirs})"
                    ));
                }
            }
            if SCIENCE.contains(&name.as_str()) && NOT_FOR_SCIENCE.contains(&dep.as_str()) {
                wrong.push(format!("{name} is science but depends on {dep}"));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// A crate's modules by path (`otsu2018::runtime`; the crate root is ``) and the file of each.
fn modules(src: &Path) -> BTreeMap<String, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let rel = path.strip_prefix(src).unwrap().with_extension("");
            let mut parts: Vec<String> = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            if matches!(
                parts.last().map(String::as_str),
                Some("mod" | "lib" | "main")
            ) {
                parts.pop();
            }
            // `bin/` targets are crates of their own; skip them.
            if parts.first().is_some_and(|p| p == "bin") {
                continue;
            }
            out.insert(parts.join("::"), path);
        }
    }
    out
}

/// The code of a file without comments and without its `#[cfg(test)]` module (tests may use
/// the whole crate).
fn code(text: &str) -> String {
    let mut out = String::new();
    let mut skip_depth: Option<i32> = None;
    let mut depth = 0i32;
    let mut pending_test = false;
    for line in text.lines() {
        let code = match line.find("//") {
            Some(i) => &line[..i],
            None => line,
        };
        let t = code.trim();
        if t == "#[cfg(test)]" {
            pending_test = true;
            continue;
        }
        if pending_test && t.starts_with("mod ") && skip_depth.is_none() {
            skip_depth = Some(depth);
        }
        pending_test = false;
        let opens = code.matches('{').count() as i32;
        let closes = code.matches('}').count() as i32;
        depth += opens - closes;
        match skip_depth {
            Some(d) if depth <= d && (opens > 0 || closes > 0) && closes >= opens => {
                skip_depth = None;
            }
            Some(_) => {}
            None => {
                out.push_str(code);
                out.push('\n');
            }
        }
    }
    out
}

/// Paths a module's code names: `crate::a::b`, `super::a`, `self::a` and `use` trees below
/// them, resolved to absolute paths (without `crate::`).
fn named_paths(module: &str, code: &str) -> Vec<String> {
    let here: Vec<&str> = if module.is_empty() {
        Vec::new()
    } else {
        module.split("::").collect()
    };
    let mut out = Vec::new();
    // Resolve `super::`/`self::`/`crate::` prefixes in every path of the text; `use` groups
    // `a::{b, c::d}` are flattened first. A name a `use crate::…::m;` brought in stands for
    // its path where it starts another (`m::f()` names `…::m::f`).
    let flat = flatten_groups(code);
    let mut aliases: BTreeMap<String, String> = BTreeMap::new();
    for line in flat.split(';') {
        let Some(tree) = line
            .trim()
            .strip_prefix("use ")
            .or(line.trim().strip_prefix("pub(crate) use "))
        else {
            continue;
        };
        for path in tree.split_whitespace() {
            if path.starts_with("crate::") || path.starts_with("super::") {
                let name = path.rsplit("::").next().unwrap_or_default();
                aliases.insert(name.to_string(), path.to_string());
            }
        }
    }
    let words = flat.split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'));
    for word in words {
        let resolved;
        let word = match word.split_once("::") {
            Some((first, rest)) if aliases.contains_key(first) => {
                resolved = format!("{}::{rest}", aliases[first]);
                resolved.as_str()
            }
            _ => word,
        };
        let parts: Vec<&str> = word.split("::").filter(|p| !p.is_empty()).collect();
        let Some(&first) = parts.first() else {
            continue;
        };
        let (mut base, rest): (Vec<&str>, &[&str]) = match first {
            "crate" => (Vec::new(), &parts[1..]),
            "super" | "self" => (here.clone(), &parts[..]),
            _ => continue,
        };
        let mut rest = rest;
        while let Some(&p) = rest.first() {
            match p {
                "super" => {
                    base.pop();
                }
                "self" => {}
                _ => break,
            }
            rest = &rest[1..];
        }
        base.extend(rest);
        out.push(base.join("::"));
    }
    out
}

/// `use a::{b, c::{d, e}};` → `use a::b a::c::d a::c::e;`
fn flatten_groups(code: &str) -> String {
    let mut out = code.to_string();
    while let Some(open) = out.find("::{") {
        // The path before the group.
        let start = out[..open]
            .rfind(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
            .map_or(0, |i| i + 1);
        let prefix = out[start..open].to_string();
        let mut depth = 0;
        let mut close = open + 2;
        for (i, c) in out[open + 2..].char_indices() {
            match c {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        close = open + 2 + i;
                        break;
                    }
                }
                _ => {}
            }
        }
        let inner = &out[open + 3..close];
        let mut items = Vec::new();
        let (mut d, mut cur) = (0, String::new());
        for c in inner.chars() {
            match c {
                '{' => d += 1,
                '}' => d -= 1,
                _ => {}
            }
            if c == ',' && d == 0 {
                items.push(std::mem::take(&mut cur));
            } else {
                cur.push(c);
            }
        }
        items.push(cur);
        let joined: Vec<String> = items
            .iter()
            .map(|s| s.trim())
            .filter(|s| !s.is_empty())
            .map(|s| {
                if s == "self" {
                    prefix.clone()
                } else {
                    format!("{prefix}::{s}")
                }
            })
            .collect();
        out.replace_range(start..=close, &joined.join(" "));
    }
    out
}

/// The module an absolute path lies in: its longest prefix that is a module, following the
/// crate root's `pub use` re-exports.
fn owner(
    path: &str,
    mods: &BTreeMap<String, PathBuf>,
    reexports: &BTreeMap<String, String>,
) -> Option<String> {
    let parts: Vec<&str> = path.split("::").collect();
    if parts.len() == 1 {
        if let Some(target) = reexports.get(parts[0]) {
            return owner(target, mods, &BTreeMap::new());
        }
    }
    (1..=parts.len())
        .rev()
        .map(|n| parts[..n].join("::"))
        .find(|p| mods.contains_key(p))
}

/// Module → modules it names, for the crate whose sources are in `src`.
fn graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mods = modules(src);
    let root_code = code(&std::fs::read_to_string(&mods[""]).unwrap());
    let mut reexports = BTreeMap::new();
    for path in named_paths(
        "",
        &flatten_groups(&root_code.replace("pub use ", "pub use crate::")),
    ) {
        if let Some(name) = path.rsplit("::").next() {
            reexports.insert(name.to_string(), path.clone());
        }
    }
    let mut g = BTreeMap::new();
    for (module, file) in &mods {
        let text = code(&std::fs::read_to_string(file).unwrap());
        let mut to = BTreeSet::new();
        if !module.is_empty() {
            for path in named_paths(module, &text) {
                if let Some(o) = owner(&path, &mods, &reexports) {
                    // A module naming its own children or itself is not a dependency on them
                    // as such; a parent's `pub mod` lines are not imports.
                    if o != *module && !o.is_empty() && !o.starts_with(&format!("{module}::")) {
                        to.insert(o);
                    }
                }
            }
        }
        g.insert(module.clone(), to);
    }
    g
}

/// A circle of `g`, if there is one.
fn circle(g: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    #[derive(Clone, Copy, PartialEq)]
    enum Mark {
        New,
        Open,
        Done,
    }
    fn visit(
        n: &str,
        g: &BTreeMap<String, BTreeSet<String>>,
        mark: &mut BTreeMap<String, Mark>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        mark.insert(n.to_string(), Mark::Open);
        path.push(n.to_string());
        for m in g.get(n).into_iter().flatten() {
            match mark.get(m).copied().unwrap_or(Mark::New) {
                Mark::Open => {
                    let i = path.iter().position(|p| p == m).unwrap();
                    let mut c = path[i..].to_vec();
                    c.push(m.clone());
                    return Some(c);
                }
                Mark::New => {
                    if let Some(c) = visit(m, g, mark, path) {
                        return Some(c);
                    }
                }
                Mark::Done => {}
            }
        }
        path.pop();
        mark.insert(n.to_string(), Mark::Done);
        None
    }
    let mut mark = BTreeMap::new();
    for n in g.keys() {
        if mark.get(n).copied().unwrap_or(Mark::New) == Mark::New {
            if let Some(c) = visit(n, g, &mut mark, &mut Vec::new()) {
                return Some(c);
            }
        }
    }
    None
}

#[test]
fn no_crate_has_a_module_circle() {
    let mut found = Vec::new();
    for manifest in manifests() {
        let src = manifest.parent().unwrap().join("src");
        if !src.is_dir() {
            continue;
        }
        let (name, _) = dependencies(&manifest);
        let g = graph(&src);
        println!("{name}:");
        for (m, to) in &g {
            if !to.is_empty() {
                let to: Vec<_> = to.iter().map(String::as_str).collect();
                println!("  {m} → {}", to.join(", "));
            }
        }
        if let Some(c) = circle(&g) {
            found.push(format!("{name}: {}", c.join(" → ")));
        }
    }
    assert!(found.is_empty(), "module circles:\n{}", found.join("\n"));
}

#[test]
fn the_checker_finds_a_circle_and_flattens_groups() {
    assert_eq!(
        flatten_groups("use crate::{a::{self, B}, c};"),
        "use crate::a crate::a::B crate::c;"
    );
    assert_eq!(
        named_paths("x::y", "super::z::f(); crate::w::V; self::k"),
        ["x::z::f", "w::V", "x::y::k"]
    );
    // A module brought in by `use` names its children through its own name (the circle
    // cmd::completions ↔ command_line hid this way).
    assert!(
        named_paths("x", "use crate::cmd;\nfn f() { cmd::completions::run(); }")
            .contains(&"cmd::completions::run".to_string())
    );
    let g: BTreeMap<String, BTreeSet<String>> = [
        ("a", vec!["b"]),
        ("b", vec!["c"]),
        ("c", vec!["a"]),
        ("d", vec![]),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v.into_iter().map(String::from).collect()))
    .collect();
    assert_eq!(circle(&g).unwrap(), ["a", "b", "c", "a"]);
    let mut dag = g.clone();
    dag.get_mut("c").unwrap().clear();
    assert_eq!(circle(&dag), None);
}
