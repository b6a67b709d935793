//! What a studio's pipeline expects of a batch's output (issue 32): texture metadata carried as
//! maketx carries it, emission maps converted as reflectance called `clipped`, `--strict` for
//! farms that gate on warnings, each kind of warning said once per batch with a count, and the
//! help saying which MIP level of the input is read. Anchored on what oiiotool and maketx
//! write and read.

use crate::runner::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The texture metadata of the issue: the four named attributes and a studio's own.
const METADATA: [(&str, &str); 5] = [
    ("Copyright", "(c) Studio 2026"),
    ("DocumentName", "rock"),
    ("ImageDescription", "rock albedo, painted"),
    ("Artist", "Ann Painter"),
    ("studio:assetId", "A-42"),
];

/// The string attributes `oiiotool --info -v` lists of `path`, by name.
fn string_attributes(path: &Path) -> BTreeMap<String, String> {
    let info = tool("oiiotool", &["--info", "-v", path.to_str().unwrap()]);
    info.lines()
        .filter_map(|l| {
            let (name, value) = l.trim().split_once(": \"")?;
            Some((name.to_string(), value.strip_suffix('"')?.to_string()))
        })
        .collect()
}

/// Of `attributes`, those [`METADATA`] names.
fn metadata_of(attributes: &BTreeMap<String, String>) -> BTreeMap<String, String> {
    METADATA
        .iter()
        .filter_map(|(k, _)| Some((k.to_string(), attributes.get(*k)?.clone())))
        .collect()
}

#[test]
fn texture_metadata_is_carried_as_maketx_carries_it_and_back_through_to_rgb() {
    let s = Scratch::new("studio-metadata");
    let input = s.path("rock.png");
    let mut args = vec![
        "--pattern",
        "fill:top=0.6,0.3,0.1:bottom=0.2,0.4,0.5",
        "16x16",
        "3",
    ];
    args.extend(["-d", "uint8"]);
    for (k, v) in METADATA {
        args.extend(["--attrib", k, v]);
    }
    args.extend(["-o", input.to_str().unwrap()]);
    tool("oiiotool", &args);
    // What maketx keeps writing an OpenEXR texture of the same file: the reference.
    let tx = s.path("rock_tx.exr");
    tool(
        "maketx",
        &[input.to_str().unwrap(), "-o", tx.to_str().unwrap()],
    );
    let want = metadata_of(&string_attributes(&tx));
    assert_eq!(
        want.len(),
        METADATA.len(),
        "maketx keeps them all: {want:?}"
    );

    let spectral = s.path("rock_spectral.exr");
    Cmd::convert(&input, &spectral).ok();
    let got = string_attributes(&spectral);
    assert_eq!(metadata_of(&got), want, "as maketx keeps them");
    // What describes the file read, not the texture, is not carried.
    assert!(!got.contains_key("Exif:ImageHistory"), "{got:?}");
    assert!(
        got.get("Software").is_none_or(|v| !v.contains("oiiotool")),
        "{got:?}"
    );

    // Back to RGB, the same metadata.
    let back = s.path("rock_rgb.exr");
    Cmd::to_rgb(&spectral, &back).ok();
    assert_eq!(metadata_of(&string_attributes(&back)), want);

    // --strip-metadata leaves it all out (and is an option of the `-u` tag).
    let stripped = s.path("rock_stripped.exr");
    Cmd::convert(&input, &stripped).arg("--strip-metadata").ok();
    assert!(metadata_of(&string_attributes(&stripped)).is_empty());

    // A data copy (OpenImageIO's make_texture, which keeps the input's header) carries the
    // same metadata as maketx, and --strip-metadata leaves it out there too.
    let copy = ["--colorspace", "Raw", "--data", "copy"];
    let copied = s.path("rock_copy.exr");
    Cmd::convert(&input, &copied).args(copy).ok();
    assert_eq!(metadata_of(&string_attributes(&copied)), want);
    let copied = s.path("rock_copy_stripped.exr");
    Cmd::convert(&input, &copied)
        .args(copy)
        .arg("--strip-metadata")
        .ok();
    let left = string_attributes(&copied);
    assert!(metadata_of(&left).is_empty(), "{left:?}");
    assert!(
        left.contains_key("specconvSettings") || left.keys().any(|k| k.starts_with("specconv")),
        "provenance kept: {left:?}"
    );
}

/// `names` in the scratch directory, each an OpenEXR of one colour brighter than white (an
/// emission map's values), as oiiotool writes it.
fn lamps(s: &Scratch, names: &[&str]) {
    let first = s.path(names[0]);
    let out = first.to_str().unwrap();
    let args = [
        "--pattern",
        "constant:color=6,3,0.5",
        "8x8",
        "3",
        "-d",
        "half",
        "-o",
        out,
    ];
    tool("oiiotool", &args);
    for name in &names[1..] {
        std::fs::copy(&first, s.path(name)).unwrap();
    }
}

#[test]
fn an_emission_map_converted_as_reflectance_is_clipped_and_strict_fails_it() {
    let s = Scratch::new("studio-clipped");
    lamps(&s, &["lamp_emit.exr", "lamp2_emit.exr"]);
    std::fs::create_dir(s.path("out")).unwrap();
    let run = Cmd::new([
        "convert",
        "lamp_emit.exr",
        "lamp2_emit.exr",
        "-o",
        "out",
        "--json",
    ])
    .current_dir(&s.0)
    .ok();
    for record in run.json_lines() {
        assert_eq!(record["status"], "clipped", "{record}");
        assert_eq!(record["above_one"], 64, "{record}");
        let warnings = record["warnings"].as_array().expect("a list");
        assert_eq!(warnings.len(), 1, "{record}");
        assert!(warnings[0].as_str().unwrap().contains("64 pixels above 1"));
    }
    // Said once for the batch, with the count, and in the summary.
    let said: Vec<&str> = run
        .stderr
        .lines()
        .filter(|l| l.contains("warning"))
        .collect();
    assert_eq!(said.len(), 2, "{}", run.stderr);
    assert!(said[0]
        .starts_with("specconv: warning: 2 inputs (the first lamp_emit.exr): 64 pixels above 1"));
    assert!(said[0].ends_with("--emissive"), "{}", said[0]);
    assert!(said[1].contains("2 converted (2 clipped)"), "{}", said[1]);

    // As emission, nothing is clipped.
    let emitted = Cmd::new([
        "convert",
        "lamp_emit.exr",
        "out/e.exr",
        "--emissive",
        "--json",
    ])
    .current_dir(&s.0)
    .ok()
    .json();
    assert_eq!(emitted["status"], "ok");
    assert_eq!(emitted["warnings"], serde_json::json!([]));

    // --strict: a failure (exit 1), and nothing written.
    let strict = s.path("strict");
    std::fs::create_dir(&strict).unwrap();
    let run = Cmd::new([
        "convert",
        "lamp_emit.exr",
        "--strict",
        "-o",
        "strict",
        "--json",
    ])
    .current_dir(&s.0)
    .run();
    run.fails(1, &[]);
    let record = run.json();
    assert_eq!(record["status"], "failed");
    let error = record["error"].as_str().unwrap();
    assert!(
        error.contains("64 pixels above 1")
            && error.contains("strict")
            && error.contains("nothing was written"),
        "{error}"
    );
    assert_eq!(std::fs::read_dir(&strict).unwrap().count(), 0);
    // The same input as emission passes --strict.
    Cmd::new([
        "convert",
        "lamp_emit.exr",
        "--strict",
        "--emissive",
        "-o",
        "strict",
    ])
    .current_dir(&s.0)
    .ok();
}

/// Writes `n` PNGs (t00.png …) whose sRGB chunk and cHRM disagree: the cHRM says Rec.2020
/// primaries. Written byte by byte as the PNG specification lays chunks out.
fn disagreeing_pngs(dir: &Path, n: usize) {
    let script = r#"
import struct, sys, zlib
def chunk(t, d):
    return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
w = h = 4
raw = b"".join(b"\x00" + bytes([200, 120, 60] * w) for _ in range(h))
chrm = struct.pack(">8I", 31270, 32900, 70800, 29200, 17000, 79700, 13100, 4600)
png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
       + chunk(b"sRGB", b"\x00") + chunk(b"gAMA", struct.pack(">I", 45455))
       + chunk(b"cHRM", chrm) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
for i in range(int(sys.argv[1])):
    open(f"{sys.argv[2]}/t{i:02}.png", "wb").write(png)
"#;
    python_output(["-c", script, &n.to_string(), dir.to_str().unwrap()]);
}

#[test]
fn forty_disagreeing_files_print_one_warning_line_with_the_count() {
    let s = Scratch::new("studio-warnings");
    disagreeing_pngs(&s.0, 40);
    // A PNG that OpenImageIO reads (it lists no cHRM; the warning is the test of it).
    let info = tool(
        "oiiotool",
        &["--info", "-v", s.path("t00.png").to_str().unwrap()],
    );
    assert!(info.contains("4 x    4, 3 channel, uint8 png"), "{info}");
    std::fs::create_dir(s.path("out")).unwrap();
    let mut names: Vec<String> = (0..40).map(|i| format!("t{i:02}.png")).collect();
    names.extend(["-o", "out", "--mip", "0", "--progress", "never"].map(String::from));
    let run = Cmd::new(&names).current_dir(&s.0).ok();
    let warnings: Vec<&str> = run
        .stderr
        .lines()
        .filter(|l| l.starts_with("specconv: warning"))
        .collect();
    assert_eq!(warnings.len(), 1, "{}", run.stderr);
    assert!(
        warnings[0].starts_with("specconv: warning: 40 inputs (the first t00.png): the file's"),
        "{}",
        warnings[0]
    );
    assert!(
        run.stderr.contains("1 kind of warning (40 inputs)"),
        "{}",
        run.stderr
    );
    // Every record lists its own.
    let json = Cmd::new([
        "t00.png", "t01.png", "-o", "out", "--force", "--mip", "0", "--json",
    ])
    .current_dir(&s.0)
    .ok()
    .json_lines();
    for r in json {
        assert_eq!(r["warnings"].as_array().map(Vec::len), Some(1), "{r}");
    }
}

#[test]
fn help_says_only_level_0_of_a_mip_mapped_input_is_read() {
    let words = |text: &str| text.split_whitespace().collect::<Vec<_>>().join(" ");
    let help = words(&Cmd::new(["convert", "--help"]).ok().stdout);
    assert!(
        help.contains("only the full-resolution level 0") && !help.contains("every MIP level)"),
        "{help}"
    );
    let man = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("man/specconv-convert.1"),
    )
    .unwrap();
    assert!(
        words(&man).contains("only the full\\-resolution level 0"),
        "the man page follows the help"
    );
}

#[test]
fn open_colorio_s_log_reaches_the_terminal_only_through_our_lines() {
    let config = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/ocio/cg-config-v1.0.0_aces-v1.3_ocio-v2.1.ocio");
    let config = config.to_str().unwrap();
    // OpenColorIO's own check logs seven lines about display spaces the config leaves inactive.
    let out = std::process::Command::new("ociocheck")
        .args(["--iconfig", config])
        .output()
        .expect("ociocheck (OpenColorIO's tools) is installed");
    let log = String::from_utf8_lossy(&out.stdout) + String::from_utf8_lossy(&out.stderr);
    let inactive = log.lines().filter(|l| l.contains("Inactive '")).count();
    assert_eq!(inactive, 7, "{log}");
    // None of them concerns a colour space a conversion can use: specconv says none.
    let s = Scratch::new("studio-ocio-log");
    let input = crate::convert::testdata("srgb8.png");
    for words in [
        vec!["--ocio", config, "info"],
        vec!["--ocio", config, "convert", "--mip", "0"],
    ] {
        let mut cmd = Cmd::new(&words).arg(&input);
        if words.contains(&"convert") {
            cmd = cmd.arg(s.path("out.exr"));
        }
        let run = cmd.ok();
        assert!(
            !run.stderr.contains("OpenColorIO"),
            "{words:?}:\n{}",
            run.stderr
        );
        assert!(
            !run.stdout.contains("OpenColorIO"),
            "{words:?}:\n{}",
            run.stdout
        );
    }
}

/// The per-channel averages `oiiotool --printstats` gives of an 8-bit picture.
fn averages(path: &Path) -> Vec<f64> {
    let stats = tool("oiiotool", &[path.to_str().unwrap(), "--printstats"]);
    let line = stats
        .lines()
        .find(|l| l.contains("Stats Avg:"))
        .expect("Avg");
    line.split_whitespace()
        .filter_map(|w| w.parse().ok())
        .take(3)
        .collect()
}

#[test]
fn preview_with_no_bounces_shows_an_emission_file_as_its_own_colour() {
    let s = Scratch::new("studio-preview-emission");
    let (input, spectral) = (s.path("lamp.exr"), s.path("lamp_spectral.exr"));
    let args = [
        "--pattern",
        "constant:color=0.5,0.2,0.1",
        "8x8",
        "3",
        "-d",
        "half",
        "-o",
    ];
    tool(
        "oiiotool",
        &[&args[..], &[input.to_str().unwrap()]].concat(),
    );
    Cmd::convert(&input, &spectral).arg("--emissive").ok();
    let shown = s.path("lamp.png");
    let run = Cmd::new(["preview"])
        .arg(&spectral)
        .arg("-o")
        .arg(&shown)
        .ok();
    assert!(run.stderr.contains("its own emission"), "{}", run.stderr);
    // The reference: OpenImageIO's own linear Rec.709 to sRGB of the input, in 8 bits.
    let reference = s.path("reference.png");
    let (i, r) = (input.to_str().unwrap(), reference.to_str().unwrap());
    tool(
        "oiiotool",
        &[
            i,
            "--colorconvert",
            "linear",
            "sRGB",
            "-d",
            "uint8",
            "-o",
            r,
        ],
    );
    let (got, want) = (averages(&shown), averages(&reference));
    for (g, w) in got.iter().zip(&want) {
        assert!((g - w).abs() <= 1.0, "{got:?} against oiiotool's {want:?}");
    }
    // Bounces need a reflectance: refused, nothing written.
    Cmd::new(["preview", "--bounces", "1", "-o"])
        .arg(s.path("bounced.png"))
        .arg(&spectral)
        .refused(&s, 1, &["holds emission", "no bounces"]);
}

#[test]
fn a_truncated_png_fails_with_our_one_line_and_nothing_from_libpng() {
    // libpng printed its own "libpng error: IDAT: Read error: hit end of file" before our
    // line (issue 32): the chunks are checked before any pixel is read.
    let s = Scratch::new("studio-truncated-png");
    let whole = s.path("whole.png");
    crate::runner::noise(&whole, 64, "uint8");
    let bytes = std::fs::read(&whole).unwrap();
    for (name, keep) in [("cut.png", 3000), ("no_end.png", bytes.len() - 12)] {
        let cut = s.path(name);
        std::fs::write(&cut, &bytes[..keep]).unwrap();
        for extra in [&[][..], &["--colorspace", "Raw", "--data", "copy"][..]] {
            Cmd::convert(&cut, s.path("o.exr"))
                .args(extra)
                .run()
                .one_error_line(1, &[name, "it is truncated"]);
            assert!(!s.path("o.exr").exists());
        }
    }
    // The whole file converts.
    Cmd::convert(&whole, s.path("o.exr")).ok();
}

#[test]
fn a_skipped_grey_map_is_named_in_the_summary_with_why_and_the_option_that_converts_it() {
    // Issue 45: a one-channel sRGB PNG albedo was skipped as data with exit 0, said only as
    // a count. The rule stands (one channel that no row from 1 to 3 calls colour is data);
    // the summary names each skipped map, why, and the option that uplifts it as colour.
    let dir = Scratch::new("grey-maps-named");
    let out = dir.path("out");
    std::fs::create_dir(&out).unwrap();
    let make = |name: &str, channels: &str, format: &str| {
        let p = dir.path(name);
        let args = [
            "--pattern",
            "fill:top=0.2:bottom=0.7",
            "8x8",
            channels,
            "-d",
            format,
            "-o",
            p.to_str().unwrap(),
        ];
        tool("oiiotool", &args);
        p
    };
    let greys = [
        make("albedo_grey.png", "1", "uint8"),
        make("albedo_grey16.png", "1", "uint16"),
        make("albedo_grey_alpha.png", "2", "uint8"),
        make("albedo_grey_tiff.tif", "1", "uint8"),
        make("albedo_grey_half.exr", "1", "half"),
    ];
    let colour = make("albedo.png", "3", "uint8");
    let mut args: Vec<&std::ffi::OsStr> = greys.iter().map(|p| p.as_os_str()).collect();
    args.extend([colour.as_os_str(), "-o".as_ref(), out.as_os_str()]);
    let run = Cmd::new(&args).ok();
    assert!(
        run.stderr
            .contains("1 converted, 0 skipped, 5 data textures skipped, 0 failed"),
        "{}",
        run.stderr
    );
    let summary = run.stderr.rsplit("specconv: 1 converted").next().unwrap();
    for grey in &greys {
        let line = summary
            .lines()
            .find(|l| l.contains(&format!("skipped as data: {}:", grey.display())))
            .unwrap_or_else(|| panic!("{} not named in {summary}", grey.display()));
        assert!(
            line.contains("one channel") && line.contains("--data copy"),
            "{line}"
        );
        // The option the line gives, followed, uplifts it as (achromatic) colour.
        let name = line
            .split("--colorspace '")
            .nth(1)
            .and_then(|s| s.split('\'').next())
            .unwrap_or_else(|| panic!("no --colorspace NAME in {line}"));
        let spectral = dir.path("one_spectral.exr");
        let records = Cmd::new([
            grey.as_os_str(),
            "--colorspace".as_ref(),
            name.as_ref(),
            spectral.as_os_str(),
            "--force".as_ref(),
            "--json".as_ref(),
        ])
        .ok()
        .json_lines();
        assert_eq!(records[0]["status"], "ok", "{line}: {records:?}");
        assert_eq!(records[0]["role"], "achromatic", "{line}");
    }
}

#[test]
fn a_data_copy_says_it_is_data_to_every_reader() {
    // Issue 45: copies were tagged "Linear" only (OpenImageIO's label of every OpenEXR file):
    // a three-channel one read back as linear Rec.709 colour. A copy carries
    // colorInteropID "data" (the OpenEXR recommendation's word for no colour), which
    // exrheader shows and specconv's `info` reads as data.
    let dir = Scratch::new("data-copy-role");
    let make = |name: &str, channels: &str, format: &str, extra: &[&str]| {
        let p = dir.path(name);
        let mut args = vec![
            "--pattern",
            "fill:top=0.2,0.5,1:bottom=0.7,0.5,1",
            "8x8",
            channels,
        ];
        args.extend(extra);
        args.extend(["-d", format, "-o", p.to_str().unwrap()]);
        tool("oiiotool", &args);
        p
    };
    let ap1 = "0.713,0.293,0.165,0.830,0.128,0.044,0.32168,0.33767";
    let cases: [(PathBuf, &[&str]); 6] = [
        (
            make("normal.png", "3", "uint8", &[]),
            &["--colorspace", "Raw"],
        ),
        (
            make("normal.exr", "3", "half", &[]),
            &["--colorspace", "raw"],
        ),
        (
            make(
                "normal_ap1.exr",
                "3",
                "half",
                &["--attrib:type=float[8]", "chromaticities", ap1],
            ),
            &["--colorspace", "Utility - Raw"],
        ),
        (make("rough.png", "1", "uint8", &[]), &[]),
        (
            make(
                "normal_tagged.exr",
                "3",
                "half",
                &["--attrib", "colorInteropID", "data"],
            ),
            &[],
        ),
        // The input's own ID is not carried over the copy's.
        (
            make(
                "normal_ap1_id.exr",
                "3",
                "half",
                &["--attrib", "colorInteropID", "lin_ap1_scene"],
            ),
            &["--colorspace", "Raw"],
        ),
    ];
    for (input, extra) in cases {
        let copy = dir.path("copy.exr");
        let mut args: Vec<&str> = vec![input.to_str().unwrap(), copy.to_str().unwrap()];
        args.extend(["--data", "copy", "--force", "--json"]);
        args.extend(extra);
        let records = Cmd::new(&args).ok().json_lines();
        assert_eq!(
            records[0]["status"],
            "copied",
            "{}: {records:?}",
            input.display()
        );
        let header = tool("exrheader", &[copy.to_str().unwrap()]);
        assert!(
            header.contains("colorInteropID (type string): \"data\""),
            "{}: {header}",
            input.display()
        );
        let v = Cmd::new(["info", "--json", copy.to_str().unwrap()])
            .ok()
            .json();
        assert_eq!(v["role"], "data", "{}: {v}", input.display());
        assert_eq!(v["colorspace"], "Raw", "{}", input.display());
    }
}

/// Writes a 16×16 PNG at `path` with the text chunks `texts` gives (Python expressions of a
/// list of (chunk type, keyword bytes, text bytes); zTXt compressed, iTXt uncompressed),
/// byte by byte as the PNG specification lays chunks out.
fn png_with_text(path: &Path, texts: &str) {
    let script = r#"
import struct, sys, zlib
def chunk(t, d):
    return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
def text(t, k, v):
    if t == b"zTXt":
        return chunk(t, k + b"\0\0" + zlib.compress(v))
    if t == b"iTXt":
        return chunk(t, k + b"\0\0\0\0\0" + v)
    return chunk(t, k + b"\0" + v)
w = h = 16
raw = b"".join(b"\x00" + bytes([200, 120, 60] * w) for _ in range(h))
png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
png += b"".join(text(*t) for t in eval("(" + sys.argv[2] + ")"))
png += chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
open(sys.argv[1], "wb").write(png)
"#;
    python_output(["-c", script, path.to_str().unwrap(), texts]);
}

/// The string attributes exrheader lists of `path` (name, value as its bytes), anchoring
/// what the file holds outside OpenImageIO.
fn exrheader_strings(path: &Path) -> BTreeMap<String, Vec<u8>> {
    let out = std::process::Command::new("exrheader")
        .arg(path)
        .output()
        .expect("exrheader is installed");
    assert!(out.status.success());
    out.stdout
        .split(|&b| b == b'\n')
        .filter_map(|l| {
            const MARK: &[u8] = b" (type string): \"";
            let at = l.windows(MARK.len()).position(|w| w == MARK)?;
            let value = l[at + MARK.len()..].strip_suffix(b"\"")?;
            Some((
                String::from_utf8_lossy(&l[..at]).into_owned(),
                value.to_vec(),
            ))
        })
        .collect()
}

/// Issue 45 items 4 and 5: a PNG with hundreds of compressed text chunks (a header of
/// megabytes) and text in each of its declared encodings. The output carries text as UTF-8
/// within the stated bounds; the rest is dropped by name in one warning; nothing else is
/// left in the directory. Anchored on exrheader's bytes and oiiotool's reading.
#[test]
fn carried_metadata_is_bounded_and_arrives_as_utf8_from_its_declared_encoding() {
    use specconv_conversion::metadata::{MAX_ATTRIBUTES, MAX_TOTAL_BYTES, MAX_VALUE_BYTES};
    let s = Scratch::new("metadata-hostile");
    let input = s.path("bomb.png");
    png_with_text(
        &input,
        r#"[(b"iTXt", b"Artist", "山田 太郎 — Café ☃".encode()),
            (b"tEXt", b"Copyright", "Café © Ø".encode("latin-1")),
            (b"zTXt", b"Description", "gravier, été".encode("latin-1")),
            (b"iTXt", b"Broken", b"Caf\xe9"),
            (b"zTXt", b"Huge", b"a" * 300000)]
           + [(b"zTXt", b"Comment%03d" % i, b"b" * 65536) for i in range(300)]"#,
    );
    assert!(
        std::fs::metadata(&input).unwrap().len() < 1 << 20,
        "the bomb is small"
    );
    let output = s.path("bomb_spectral.exr");
    let run = Cmd::convert(&input, &output).ok();
    let warnings: Vec<&str> = run
        .stderr
        .lines()
        .filter(|l| l.starts_with("specconv: warning"))
        .collect();
    assert_eq!(warnings.len(), 1, "{}", run.stderr);
    for needle in [
        "'Broken' (not UTF-8 text)",
        "'Huge' (values over 64 KiB)",
        "--strip-metadata",
    ] {
        assert!(warnings[0].contains(needle), "{needle}: {}", warnings[0]);
    }
    assert_eq!(
        s.files(),
        ["bomb.png", "bomb_spectral.exr"],
        "no temporary left"
    );
    let strings = exrheader_strings(&output);
    assert_eq!(strings["Artist"], "山田 太郎 — Café ☃".as_bytes());
    assert_eq!(strings["Copyright"], "Café © Ø".as_bytes());
    assert_eq!(strings["ImageDescription"], "gravier, été".as_bytes());
    assert!(!strings.contains_key("Broken") && !strings.contains_key("Huge"));
    let comments: Vec<&String> = strings
        .keys()
        .filter(|k| k.starts_with("Comment"))
        .collect();
    let carried: usize = strings
        .iter()
        .filter(|(k, _)| !k.starts_with("specconv"))
        .map(|(k, v)| k.len() + v.len())
        .sum();
    assert!(comments.len() + 3 <= MAX_ATTRIBUTES, "{}", comments.len());
    assert!(carried <= MAX_TOTAL_BYTES + 4096, "{carried} bytes carried");
    assert!(strings.values().all(|v| v.len() <= MAX_VALUE_BYTES));
    assert!(std::fs::metadata(&output).unwrap().len() < 4 << 20);
    // OpenImageIO reads the same text.
    let info = tool("oiiotool", &["--info", "-v", output.to_str().unwrap()]);
    assert!(info.contains("Artist: \"山田 太郎 — Café ☃\""), "{info}");
    assert!(info.contains("Copyright: \"Café © Ø\""), "{info}");
    // A data copy (make_texture, which copies the input's header) drops the same.
    let copy = s.path("bomb_copy.exr");
    Cmd::convert(&input, &copy)
        .args(["--colorspace", "Raw", "--data", "copy"])
        .ok();
    let copied = exrheader_strings(&copy);
    assert!(!copied.contains_key("Huge") && !copied.contains_key("Broken"));
    assert!(std::fs::metadata(&copy).unwrap().len() < 4 << 20);
    // OpenImageIO writes Copyright as OpenEXR's `owner` and reads it back as Copyright.
    assert_eq!(copied["owner"], "Café © Ø".as_bytes(), "as UTF-8");
    assert_eq!(string_attributes(&copy)["Copyright"], "Café © Ø");
    // A compact file, and its expansion, carry the same.
    let compact = s.path("bomb_compact.exr");
    Cmd::convert(&input, &compact)
        .args(["--layout", "compact"])
        .ok();
    let expanded = s.path("bomb_expanded.exr");
    Cmd::new(["expand"]).arg(&compact).arg(&expanded).ok();
    for file in [&compact, &expanded] {
        let got = exrheader_strings(file);
        assert_eq!(got["Artist"], strings["Artist"], "{}", file.display());
        let keys = |m: &BTreeMap<String, Vec<u8>>| {
            m.keys()
                .filter(|k| !k.starts_with("specconv") && !k.starts_with("oiio"))
                .filter(|k| k.starts_with('C') || k.starts_with('A') || k.starts_with('I'))
                .cloned()
                .collect::<Vec<_>>()
        };
        assert_eq!(keys(&got), keys(&strings), "{}", file.display());
    }
}

/// Issue 57, items 8 and 9: OpenImageIO writes UTF-8 into a PNG's `tEXt` (and reads it back
/// as UTF-8): it arrives as that text, not as Latin-1 mojibake, while Latin-1 bytes stay
/// Latin-1; `tEXt` keywords under OpenEXR's `name` and `compression` are dropped with the
/// warning OpenEXR's other names get. Anchored on oiiotool's reading and exrheader's bytes.
#[test]
fn png_text_in_utf8_stays_utf8_and_dropped_keywords_are_said() {
    let s = Scratch::new("png-text-utf8");
    let text = "山田 太郎 — Café ☃";
    let written = s.path("oiio.png");
    tool(
        "oiiotool",
        &[
            "--pattern",
            "constant:color=0.5,0.4,0.3",
            "8x8",
            "3",
            "--attrib",
            "Copyright",
            text,
            "-d",
            "uint8",
            "-o",
            written.to_str().unwrap(),
        ],
    );
    let read = tool("oiiotool", &["--info", "-v", written.to_str().unwrap()]);
    assert!(read.contains(&format!("Copyright: \"{text}\"")), "{read}");
    let out = s.path("oiio_spectral.exr");
    Cmd::convert(&written, &out).ok();
    assert_eq!(exrheader_strings(&out)["Copyright"], text.as_bytes());
    let input = s.path("keys.png");
    png_with_text(
        &input,
        r#"[(b"tEXt", b"name", b"part one"),
            (b"tEXt", b"compression", b"none, please"),
            (b"tEXt", b"Comment", "Café".encode("latin-1"))]"#,
    );
    let out = s.path("keys_spectral.exr");
    let run = Cmd::convert(&input, &out).ok();
    let warning = run
        .stderr
        .lines()
        .find(|l| l.starts_with("specconv: warning"))
        .unwrap_or_else(|| panic!("no warning: {}", run.stderr));
    assert!(
        warning.contains("'name'") && warning.contains("'compression'"),
        "{warning}"
    );
    let strings = exrheader_strings(&out);
    assert_eq!(strings["Comment"], "Café".as_bytes());
    assert_ne!(
        strings.get("compression").map(Vec::as_slice),
        Some(&b"none, please"[..])
    );
}

/// Issue 45 item 6: an input attribute under any of OpenEXR's own names (the `exr` crate's
/// list of required and standard attributes) or a name outside Latin-1 no longer fails the
/// input: the names OpenEXR cannot take are dropped, named in one warning for the batch, and
/// the rest is carried.
#[test]
fn openexr_s_own_names_are_dropped_by_name_and_the_rest_carried_once_per_batch() {
    let s = Scratch::new("metadata-reserved");
    let own: Vec<String> = exr::meta::header::standard_names::ALL
        .iter()
        .map(|n| String::from_utf8(n.to_vec()).unwrap())
        .collect();
    let chunks = |names: &[String]| {
        let list: Vec<String> = names
            .iter()
            .map(|n| format!("(b\"tEXt\", b\"{n}\", b\"x\")"))
            .collect();
        format!("[(b\"tEXt\", b\"Artist\", b\"Ann\"), {}]", list.join(", "))
    };
    let (first, second) = own.split_at(own.len() / 2);
    png_with_text(&s.path("a.png"), &chunks(first));
    png_with_text(&s.path("b.png"), &chunks(second));
    // A name outside Latin-1, as OpenImageIO writes it into an OpenEXR.
    tool(
        "oiiotool",
        &[
            "--pattern",
            "constant:color=0.5,0.4,0.3",
            "16x16",
            "3",
            "--attrib",
            "studio:名前",
            "岩 ☃",
            "-o",
            s.path("c.exr").to_str().unwrap(),
        ],
    );
    std::fs::create_dir(s.path("out")).unwrap();
    let run = Cmd::new(["a.png", "b.png", "c.exr", "-o", "out", "--mip", "0"])
        .current_dir(&s.0)
        .ok();
    let warnings: Vec<&str> = run
        .stderr
        .lines()
        .filter(|l| l.starts_with("specconv: warning"))
        .collect();
    assert_eq!(warnings.len(), 1, "{}", run.stderr);
    assert!(warnings[0].contains("2 inputs"), "{}", warnings[0]);
    assert!(
        warnings[0].contains("OpenEXR's own attribute names"),
        "{}",
        warnings[0]
    );
    // Every name of both inputs, those the writer makes itself (`compression`, `name`,
    // `wrapmodes`) too: the PNG's text under them is the file's words (issue 57, item 8).
    for name in &own {
        let named = warnings[0].contains(&format!("'{name}'"));
        assert!(named, "{name}: {}", warnings[0]);
    }
    for (stem, names) in [("a", first), ("b", second)] {
        let out = s.path(&format!("out/{stem}_spectral.exr"));
        let strings = exrheader_strings(&out);
        assert_eq!(strings["Artist"], b"Ann", "{stem}");
        let info = tool("oiiotool", &["--info", "-v", out.to_str().unwrap()]);
        for name in names {
            // Where OpenEXR's attribute is a string, it is the writer's own, never "x".
            assert!(strings.get(name).is_none_or(|v| v != b"x"), "{name}");
            assert!(!info.contains(&format!("{name}: \"x\"")), "{name}: {info}");
        }
    }
    let strings = exrheader_strings(&s.path("out/c_spectral.exr"));
    assert_eq!(strings["studio:名前"], "岩 ☃".as_bytes());
    // --strict makes it a failure, as every warning, and writes nothing.
    std::fs::create_dir(s.path("strict")).unwrap();
    Cmd::new(["a.png", "-o", "strict", "--strict"])
        .current_dir(&s.0)
        .fails(1, &["'tiles'", "strict", "nothing was written"]);
    assert_eq!(std::fs::read_dir(s.path("strict")).unwrap().count(), 0);
}
