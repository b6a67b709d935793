//! The colour shift of `eval` (CIEDE2000 between a measured spectrum and its uplift, lit by
//! another illuminant) against colour-science 0.4.7's own tables and formulas: the CIE 1931 2°
//! observer, illuminants A and FL11, `sd_to_XYZ` (integration), `XYZ_to_Lab` and `delta_E`
//! (CIE 2000), on the ColorChecker's 24 spectra and their uplifts by the built-in model.

use specconv_colour::{Colorimetry, Illuminant};
use specconv_evaluation::eval::{self, Viewing};
use specconv_spectral::{Method, Model, Uplifter};

const SCRIPT: &str = r#"
import json, sys, warnings
import numpy as np
warnings.simplefilter("ignore")
import colour

case = json.load(open(sys.argv[1]))
shape = colour.SpectralShape(case["start"], case["end"], case["step"])
cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
out = {}
for name in case["illuminants"]:
    ill = colour.SDS_ILLUMINANTS[name].copy().align(shape)
    def xyz(values):
        sd = colour.SpectralDistribution(dict(zip(shape.wavelengths, values)))
        return colour.sd_to_XYZ(sd, cmfs, ill, method="Integration") / 100
    white = xyz(np.ones(len(shape.wavelengths)))
    xy = colour.XYZ_to_xy(white)
    de = [
        float(colour.delta_E(colour.XYZ_to_Lab(xyz(s), xy), colour.XYZ_to_Lab(xyz(r), xy), method="CIE 2000"))
        for s, r in zip(case["measured"], case["uplifted"])
    ]
    out[name] = {"per_spectrum": de, "mean": float(np.mean(de)),
                 "p95": float(np.percentile(de, 95)), "max": float(np.max(de))}
print(json.dumps(out))
"#;

#[test]
fn colour_shift_agrees_with_colour_science() {
    let model = Model::builtin();
    let a: Colorimetry = model.colorimetry().unwrap();
    let up = Uplifter::new(model).unwrap();
    let set = specconv_testkit::set(specconv_testkit::COLORCHECKER, &a.grid);
    let viewing = Viewing::new(&a, &[Illuminant::A, Illuminant::FL11]).unwrap();
    let outcomes = eval::evaluate(&a, &up, &set.spectra, &viewing);
    let summary = eval::summarise(&outcomes);
    let mut r = vec![0.0; a.bands()];
    let uplifted: Vec<Vec<f64>> = set
        .spectra
        .iter()
        .map(|s| {
            up.uplift_f64(&a.xyz(s), &mut r);
            r.clone()
        })
        .collect();
    let case = serde_json::json!({
        "start": a.grid.start, "end": a.grid.end, "step": a.grid.step,
        "illuminants": ["A", "FL11"],
        "measured": set.spectra,
        "uplifted": uplifted,
    });
    let dir = std::env::temp_dir().join(format!("specconv-shift-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("case.json");
    std::fs::write(&path, case.to_string()).unwrap();
    let out = specconv_testkit::cmd::python_output(["-c", SCRIPT, path.to_str().unwrap()]);
    let _ = std::fs::remove_dir_all(&dir);
    let theirs: serde_json::Value = serde_json::from_slice(&out).unwrap();
    let mut worst = 0f64;
    for (k, name) in ["A", "FL11"].iter().enumerate() {
        let t = &theirs[name];
        for (i, o) in outcomes.iter().enumerate() {
            let want = t["per_spectrum"][i].as_f64().unwrap();
            worst = worst.max((o.colour_shift[k].ciede2000 - want).abs());
        }
        let s = &summary.colour_shift[k];
        assert_eq!(s.illuminant.to_string(), *name);
        for (ours, key) in [(s.mean, "mean"), (s.p95, "p95"), (s.max, "max")] {
            let want = t[key].as_f64().unwrap();
            assert!(
                (ours - want).abs() < 1e-9,
                "{name} {key}: {ours} against {want}"
            );
        }
        // The uplift is not the measured spectrum: there is a shift to measure.
        assert!(s.mean > 0.05, "{name}: {s:?}");
    }
    eprintln!("colour shift: max |ours − colour-science| = {worst:.2e} ΔE00");
    // The same CIE tables on both sides (ours from ../shared/cie, colour-science's own copies),
    // the same sums: they agree to rounding (1.2e-13 measured).
    assert!(worst < 1e-9, "{worst}");
}
