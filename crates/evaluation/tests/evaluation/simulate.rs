//! The paper's Fig. 1 and 12 in numbers: Munsell chips in a 5500 K furnace, each uplifted from
//! the colour a texture would store (its XYZ under the model's D65 colorimetry), drift from the
//! measured spectrum's rendering as light bounces. The paper's setting: its model, trained on
//! these chips (the default `open` never saw them: docs/simulate.md has its figures).

use specconv_colour::Illuminant;
use specconv_evaluation::simulate::{furnace, simulate, Effect, Light, Material, Scene};
use specconv_spectral::baselines::{Meng2015, Smits1999};
use specconv_spectral::{Model, Uplifter};

#[test]
fn munsell_furnace_at_5500k_drifts_for_smooth_methods_and_least_for_otsu2018() {
    let model = Model::builtin_named("paper").unwrap();
    let a = model.colorimetry().unwrap();
    let spectra = specconv_testkit::set(specconv_testkit::MUNSELL, &a.grid);
    let n = spectra.spectra.len();
    let scene = Scene {
        names: spectra.names.clone(),
        materials: spectra
            .spectra
            .iter()
            .cloned()
            .map(Material::Measured)
            .collect(),
        form_factors: furnace(n),
        lights: vec![Light {
            name: "blackbody:5500".into(),
            spd: Illuminant::Blackbody(5500.0).spd(&a.grid).unwrap(),
            power: 1.0,
            patches: (0..n).collect(),
        }],
        effect: Effect::Bounces(8),
    };
    let otsu = Uplifter::new(model).unwrap();
    let smits = Smits1999::new(&a).unwrap();
    let meng = Meng2015::new(&a, false).unwrap();
    let out = simulate(
        &scene,
        &a,
        &[
            ("otsu2018", &otsu),
            ("smits1999", &smits),
            ("meng2015", &meng),
        ],
    )
    .unwrap();
    let mean = |m: &str| out.mean_delta_e(m, "measured").unwrap();
    let (o, s, m, rgb) = (
        mean("otsu2018"),
        mean("smits1999"),
        mean("meng2015"),
        mean("rgb"),
    );
    for k in 0..=8 {
        eprintln!(
            "K={k}: otsu2018 {:.4} smits1999 {:.4} meng2015 {:.4} rgb {:.4}",
            o[k], s[k], m[k], rgb[k]
        );
    }
    // No bounce: everyone sees the light itself.
    assert!(o[0] < 1e-9 && s[0] < 1e-9 && m[0] < 1e-9);
    for k in 1..=8 {
        assert!(
            o[k] < s[k] && o[k] < m[k],
            "K={k}: {} {} {}",
            o[k],
            s[k],
            m[k]
        );
        if k > 1 {
            assert!(
                s[k] > s[k - 1] && m[k] > m[k - 1],
                "K={k}: growth {s:?} {m:?}"
            );
        }
    }
}
