//! The conversion library alone (`specconv_conversion`) converts with the command line's
//! bytes: a second front-end (Python, a renderer plugin, a farm worker) calling the library
//! gets what `specconv` writes, and each call's report is its own.

use crate::convert::testdata;
use specconv_conversion::plan::Pair;
use specconv_conversion::{
    Batch, Compression, Converter, Event, Mip, Options, Provenance, Rounding, Sample,
};
use specconv_testkit::cmd::{Cmd, Scratch};

fn bytes(p: &std::path::Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Sets on [`Options`] what a case's flags say.
type SetOptions = Box<dyn Fn(&mut Options)>;

#[test]
fn the_library_alone_writes_the_command_lines_bytes() {
    let dir = Scratch::new("library-bytes");
    // (input, the CLI's options, the same options set on the library's Options)
    let cases: Vec<(&str, Vec<&str>, SetOptions)> = vec![
        ("srgb8.png", vec![], Box::new(|_| {})),
        // Every MIP level of a maketx texture, alpha, float.
        (
            "float_alpha.tx",
            vec!["-d", "float"],
            Box::new(|o| o.sample = Sample::Float),
        ),
        (
            "srgba8.tx",
            vec!["--emissive", "--compression", "piz"],
            Box::new(|o| {
                o.emission = Some(specconv_colour::EmissionUnits::Reference);
                o.compression = Compression::Piz;
            }),
        ),
        (
            "rgb16.tif",
            vec![
                "--mip",
                "0",
                "--half-rounding",
                "colour",
                "--unbounded",
                "-j",
                "1",
            ],
            Box::new(|o| {
                o.mip = Mip::Base;
                o.rounding = Some(Rounding::Colour);
                o.bounded = false;
                o.threads = Some(1);
            }),
        ),
    ];
    for (i, (input, flags, set)) in cases.iter().enumerate() {
        let input = testdata(input);
        let by_cli = dir.path(&format!("cli-{i}.exr"));
        Cmd::convert(&input, &by_cli).args(flags).ok();
        let mut options = Options::default();
        set(&mut options);
        let by_library = dir.path(&format!("library-{i}.exr"));
        let report = Converter::new(options)
            .unwrap()
            .convert(&input, &by_library)
            .unwrap();
        assert!(report.pixels > 0);
        // The same bytes but for the one attribute that names the input's file… which is the
        // same file: the whole files are equal.
        assert!(
            bytes(&by_cli) == bytes(&by_library),
            "{}: {flags:?} differs between the CLI and the library",
            input.display()
        );
    }
}

#[test]
fn each_conversion_reports_its_own_counts_and_batches_skip_what_is_up_to_date() {
    let dir = Scratch::new("library-batch");
    let converter = Converter::new(Options::default()).unwrap();
    // A saturated input has projected and outside pixels; converting it does not add to the
    // next conversion's counts (they were shared on the method before).
    let photo = converter
        .convert(&testdata("photo.jpg"), &dir.path("photo.exr"))
        .unwrap();
    let grey = converter
        .convert(&testdata("srgb8.png"), &dir.path("grey.exr"))
        .unwrap();
    let again = converter
        .convert(&testdata("photo.jpg"), &dir.path("photo2.exr"))
        .unwrap();
    let (p, a) = (photo.bounded.unwrap(), again.bounded.unwrap());
    assert_eq!(p, a, "the same input, the same counts");
    let g = grey.bounded.unwrap();
    assert_eq!(
        (g.in_range + g.projected + g.outside + g.not_finite) as u64,
        grey.pixels,
        "every pixel of this call counted once, none of the others'"
    );
    // Provenance reads back what the CLI's -u compares.
    let attrs = specconv_exr::read_attributes(&dir.path("grey.exr")).unwrap();
    let recorded = Provenance::from_attributes(&attrs).unwrap();
    assert_eq!(recorded.settings, converter.provenance().settings);
    assert_eq!(recorded.source.as_deref(), Some("srgb8.png"));

    // A batch: the first run converts, -u skips what the CLI made with the same settings.
    let inputs = ["srgb8.png", "rgb16.png"];
    let pairs: Vec<Pair> = inputs
        .iter()
        .map(|i| Pair::new(testdata(i), dir.path(&format!("{i}.exr"))))
        .collect();
    Cmd::convert(&pairs[0].input, &pairs[0].output).ok();
    let mut events = Vec::new();
    let summary = Batch::new(&converter)
        .update(true)
        .run(&pairs, &mut |e| match e {
            Event::Skipped { .. } => events.push("skipped"),
            Event::Converted { .. } => events.push("converted"),
            Event::Failed { .. } => events.push("failed"),
            _ => {}
        })
        .unwrap();
    assert_eq!(events, ["skipped", "converted"]);
    assert_eq!(
        (summary.converted, summary.skipped, summary.failed),
        (1, 1, 0)
    );
    // Without update an existing output is refused, by cause.
    let refused = converter
        .convert(&pairs[0].input, &pairs[0].output)
        .unwrap_err();
    assert_eq!(
        refused.remedy(),
        Some(specconv_conversion::Remedy::ReplaceOrSkip)
    );
    assert!(!refused.to_string().contains("--"), "{refused}");
    // A batch whose plan breaks a rule is refused whole, before any event, by cause.
    let onto_input = vec![
        pairs[0].clone(),
        Pair::new(&pairs[0].output, dir.path("x.exr")),
    ];
    let mut events = 0;
    let refused = Batch::new(&converter)
        .update(true)
        .run(&onto_input, &mut |_| events += 1)
        .unwrap_err();
    assert_eq!(events, 0);
    assert!(refused.to_string().contains("is the input"), "{refused}");
}

/// `to-rgb` through the library stops when its cancel flag is set (a signal in the CLI, a
/// front-end's stop button): `is_cancelled`, nothing published and no temporary left; the
/// same call without the flag writes what the command line writes.
#[test]
fn a_cancelled_integration_writes_nothing() {
    use specconv_conversion::to_rgb::{ToRgb, ToRgbOptions};
    use std::sync::atomic::AtomicBool;
    let dir = Scratch::new("library-to-rgb-cancel");
    let spectral = dir.path("s.exr");
    Cmd::convert(testdata("srgb8.png"), &spectral).ok();
    let to_rgb = ToRgb::new(ToRgbOptions::default()).unwrap();
    let out = dir.path("rgb.exr");
    let e = to_rgb
        .convert_cancellable(&spectral, &out, &AtomicBool::new(true))
        .unwrap_err();
    assert!(e.is_cancelled(), "{e}");
    assert_eq!(dir.files(), ["s.exr"], "nothing published, no temporary");
    to_rgb
        .convert_cancellable(&spectral, &out, &AtomicBool::new(false))
        .unwrap();
    let by_cli = dir.path("cli.exr");
    Cmd::new(["to-rgb"]).arg(&spectral).arg(&by_cli).ok();
    assert_eq!(bytes(&out), bytes(&by_cli));
}
