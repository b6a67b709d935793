//! What a user meets around the compact layout and maketx habits (issue 45, items 15 and 17):
//! every reader of spectral files names a compact texture as one and points to `expand`;
//! `expand` is a batch as `convert` is; maketx's spellings are accepted where the meaning
//! exists; `train` says what it records of a set's commercial terms, as its help does.

use crate::runner::{colorchecker, no_temporaries};
use specconv_testkit::cmd::{json, tool, Cmd, Scratch};
use std::path::{Path, PathBuf};

fn image(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata/images")
        .join(name)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Compact files as a user may meet them: as written, with alpha, from a newer version
/// (`compact 9`), with the layout attribute lost (a tool that drops unknown attributes), and
/// with the decoding text lost.
fn compact_variants(dir: &Scratch) -> Vec<(&'static str, PathBuf)> {
    let plain = dir.path("plain_compact.exr");
    Cmd::convert(image("srgb8.png"), &plain)
        .args(["--layout", "compact"])
        .ok();
    let alpha = dir.path("alpha_compact.exr");
    Cmd::convert(image("srgba8.png"), &alpha)
        .args(["--layout", "compact"])
        .ok();
    let mut all = vec![("as written", plain.clone()), ("with alpha", alpha)];
    for (name, edit) in [
        ("newer", &["--sattrib", "specconvLayout", "compact 9"][..]),
        (
            "no layout attribute",
            &["--eraseattrib", "specconvLayout"][..],
        ),
        (
            "no decoding text",
            &["--eraseattrib", "specconvCompact"][..],
        ),
    ] {
        let out = dir.path(&format!("{}.exr", name.replace(' ', "_")));
        let mut args = vec![s(&plain)];
        args.extend_from_slice(edit);
        args.extend_from_slice(&["-o", s(&out)]);
        tool("oiiotool", &args);
        all.push((name, out));
    }
    all
}

#[test]
fn every_reader_of_spectral_files_names_a_compact_texture_and_expand() {
    let dir = Scratch::new("front-compact-readers");
    let mut cases = 0;
    for (what, file) in compact_variants(&dir) {
        // info: the layout, the bands its header decodes to (or why not), the texel, expand.
        let out = Cmd::new(["info"]).arg(&file).ok().stdout;
        for needle in [
            "compact layout",
            "texel:",
            "R, G, B, U.0, U.1, U.2, UF.0, UF.1, UF.2",
            "specconv expand",
        ] {
            assert!(
                out.contains(needle),
                "{what}: info lacks {needle:?}:\n{out}"
            );
        }
        let decodable = matches!(what, "as written" | "with alpha");
        let bands = "36, 380 to 730 nm, every 10 nm";
        if what == "no layout attribute" {
            // The channels say compact; the header's own check says what is missing.
            assert!(
                out.contains("not decodable by this version: no specconvLayout"),
                "{out}"
            );
        } else {
            assert_eq!(out.contains(bands), decodable, "{what}:\n{out}");
        }
        assert!(
            !out.contains("colour space:"),
            "{what}: read as colour:\n{out}"
        );
        let record = Cmd::new(["info", "--json"]).arg(&file).ok().json();
        let compact = &record["compact"];
        assert!(compact.is_object(), "{what}: {record}");
        assert_eq!(compact["texel_channels"].as_array().unwrap().len(), 9);
        if decodable {
            assert_eq!(compact["bands_nm"].as_array().unwrap().len(), 36, "{what}");
        } else {
            assert!(compact["problem"].is_string(), "{what}: {compact}");
        }
        // to-rgb and preview: one line that says what the file is and what makes its bands.
        let rgb = dir.path("rgb.exr");
        Cmd::to_rgb(&file, &rgb).refused(&dir, 1, &["is a compact texture", "`expand`"]);
        Cmd::new(["preview"])
            .arg(&file)
            .args(["-o", s(&dir.path("p.png"))])
            .refused(&dir, 1, &["is a compact texture", "`expand`"]);
        cases += 3;
    }
    // What expand writes is read by both.
    let plain = dir.path("plain_compact.exr");
    let spectral = dir.path("plain_spectral.exr");
    Cmd::new(["expand"]).arg(&plain).arg(&spectral).ok();
    Cmd::to_rgb(&spectral, dir.path("rgb.exr")).ok();
    // A file that is neither still gets the plain reason.
    Cmd::to_rgb(image("half_scanline.exr"), dir.path("rgb2.exr")).fails(1, &["not a spectral EXR"]);
    assert!(cases >= 15);
}

#[test]
fn expand_is_a_batch_as_convert_is() {
    let dir = Scratch::new("front-expand-batch");
    let mut inputs = Vec::new();
    for name in ["srgb8.png", "srgba8.png", "rgb16.png"] {
        let out = dir.path(&name.replace(".png", "_compact.exr"));
        Cmd::convert(image(name), &out)
            .args(["--layout", "compact"])
            .ok();
        inputs.push(out);
    }
    let outdir = dir.path("spectral");
    let expand = || {
        Cmd::new(["expand", "-j", "1", "--json", "-o", s(&outdir)])
            .args(inputs.iter().map(|p| s(p)))
    };
    // -o DIR into a directory that does not exist yet? convert's rule: it is made or refused
    // alike; make it as a user would.
    std::fs::create_dir_all(&outdir).unwrap();
    let records = expand().ok().json_lines();
    assert_eq!(records.len(), 3);
    for (r, input) in records.iter().zip(&inputs) {
        assert_eq!(r["status"], "ok", "{r}");
        assert_eq!(r["bands"], 36, "{r}");
        assert_eq!(r["input"], s(input));
        let out = PathBuf::from(r["output"].as_str().unwrap());
        assert!(out.starts_with(&outdir) && out.exists(), "{r}");
        assert!(tool("iinfo", &["-v", s(&out)]).contains("T.380"), "{r}");
    }
    // -u: all up to date; without it (and without --force) the existing outputs are refused
    // before anything is written.
    for r in expand().arg("-u").ok().json_lines() {
        assert_eq!(r["status"], "skipped", "{r}");
    }
    expand().fails(2, &["--force"]);
    expand().arg("--force").ok();
    // A failed input does not stop the others: exit 1, the others expanded.
    let spectral = dir.path("not_compact_spectral.exr");
    Cmd::convert(image("srgb8.png"), &spectral).ok();
    let out = Cmd::new(["expand", "--force", "-o", s(&outdir)])
        .arg(&spectral)
        .args(inputs.iter().map(|p| s(p)))
        .run();
    out.fails(1, &["not a compact texture"]);
    assert!(
        out.stderr.contains("3 expanded, 0 skipped, 1 failed"),
        "{}",
        out.stderr
    );
    // Inputs from standard input, one a line, as convert reads them.
    let list: String = inputs.iter().map(|p| format!("{}\n", s(p))).collect();
    let records = Cmd::new(["expand", "--json", "--force", "-o", s(&outdir), "-"])
        .stdin(list)
        .ok()
        .json_lines()
        .len();
    assert_eq!(records, 3);
    // INPUT OUTPUT still; and a lone input is a usage error that says what to give.
    Cmd::new(["expand"])
        .arg(&inputs[0])
        .arg(dir.path("one.exr"))
        .ok();
    Cmd::new(["expand"]).arg(&inputs[0]).fails(2, &["-o DIR"]);
    no_temporaries(&outdir);
}

/// maketx's spellings whose meaning specconv has give the bytes of specconv's own flag (the
/// settings tag each output records is the same).
#[test]
fn maketx_spellings_are_accepted_where_the_meaning_exists() {
    let dir = Scratch::new("front-maketx");
    let png = image("srgba8.png");
    let settings = |args: &[&str], name: &str| {
        let out = dir.path(name);
        Cmd::convert(&png, &out).args(args).arg("--force").ok();
        let info = Cmd::new(["info", "--json"]).arg(&out).ok().json();
        info["spectral"]["specconv"]["specconvSettings"].clone()
    };
    let mut pairs = 0;
    for (maketx, ours) in [
        (&["--nomipmap"][..], &["--mip", "0"][..]),
        (&["--noresize"][..], &[][..]),
        (&["--ignore-unassoc"][..], &["--alpha", "premultiplied"][..]),
        (&["--colorconfig", "aces"][..], &["--ocio", "aces"][..]),
        (&["--fixnan", "none"][..], &["--fixnan", "keep"][..]),
        (&["--checknan"][..], &["--fixnan", "refuse"][..]),
    ] {
        let a = settings(maketx, "a.exr");
        let b = settings(ours, "b.exr");
        assert!(a.is_string(), "{maketx:?}: {a}");
        assert_eq!(a, b, "{maketx:?} against {ours:?}");
        pairs += 1;
    }
    assert_eq!(pairs, 6);
    // --nomipmap is one level, and it is in --help.
    let out = dir.path("one.exr");
    Cmd::convert(&png, &out).arg("--nomipmap").ok();
    let levels = Cmd::new(["info", "--json"]).arg(&out).ok().json()["mip_levels"].clone();
    assert_eq!(levels.as_array().unwrap().len(), 1, "{levels}");
    let help = Cmd::new(["convert", "--help"]).ok().stdout;
    for flag in [
        "--nomipmap",
        "--noresize",
        "--ignore-unassoc",
        "colorconfig",
    ] {
        assert!(help.contains(flag), "--help lacks {flag}");
    }
}

/// `train` on a set of the user's own, without --commercial, records and says "unstated", and
/// the help says so (not "yes").
#[test]
fn train_says_what_it_records_of_commercial_use_as_its_help_does() {
    let dir = Scratch::new("front-commercial");
    let own = dir.path("swatches.csv");
    std::fs::copy(colorchecker(), &own).unwrap();
    let model = dir.path("m.json");
    let said = Cmd::train(&own)
        .args(["--clusters", "1", "-o", s(&model)])
        .ok();
    let said = &said.stderr;
    assert!(said.contains("commercial use: unstated"), "{said}");
    assert!(said.contains("--commercial yes"), "{said}");
    let m = json(&std::fs::read_to_string(&model).unwrap());
    assert_eq!(m["training"]["sets"][0]["commercial"], "unstated", "{m}");
    let help = Cmd::new(["train", "--help"]).ok().stdout;
    let para = help.split("--commercial").nth(1).unwrap();
    let para = &para[..para.find("\n\n").unwrap_or(para.len())];
    assert!(para.contains("else unstated"), "{para}");
    assert!(!para.contains("measurements: yes"), "{para}");
    // With --commercial yes: yes.
    let said = Cmd::train(&own)
        .args([
            "--clusters",
            "1",
            "--commercial",
            "yes",
            "--force",
            "-o",
            s(&model),
        ])
        .ok();
    assert!(
        said.stderr.contains("commercial use: yes"),
        "{}",
        said.stderr
    );
}
