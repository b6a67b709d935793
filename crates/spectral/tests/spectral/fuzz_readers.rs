//! The CSV and model readers take untrusted files: random damage to valid files must give an
//! error or a valid result, never a panic. (Property tests with byte-level mutations: deleting,
//! duplicating, replacing and truncating, including multi-byte characters.)

use proptest::prelude::*;
use specconv_colour::SpectralTable;
use specconv_spectral::Model;

fn valid_csv() -> String {
    let mut s = String::from("wavelength_nm,\"a, quoted\",b,c\n");
    for w in (380..=730).step_by(10) {
        s.push_str(&format!("{w},0.{},{}e-1,0.5\n", w % 97, w % 7));
    }
    s
}

/// Applies edits at positions given as fractions of the length, keeping the text valid UTF-8.
fn mutate(text: &str, edits: &[(u8, f64, char)]) -> String {
    let mut chars: Vec<char> = text.chars().collect();
    for &(kind, at, ch) in edits {
        if chars.is_empty() {
            chars.push(ch);
            continue;
        }
        let i = ((at * chars.len() as f64) as usize).min(chars.len() - 1);
        match kind % 5 {
            0 => {
                chars.remove(i);
            }
            1 => chars.insert(i, ch),
            2 => chars[i] = ch,
            3 => chars.truncate(i),
            _ => {
                let dup: Vec<char> = chars[i..(i + 40).min(chars.len())].to_vec();
                chars.splice(i..i, dup);
            }
        }
    }
    chars.into_iter().collect()
}

fn edit() -> impl Strategy<Value = (u8, f64, char)> {
    (
        any::<u8>(),
        0.0f64..1.0,
        prop::sample::select(vec![
            ',', '\n', '"', '-', '.', 'e', '0', '9', '{', '}', '[', ']', ':', 'μ', ' ', '\r', 'x',
        ]),
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn damaged_csv_never_panics(edits in prop::collection::vec(edit(), 1..8)) {
        let text = mutate(&valid_csv(), &edits);
        if let Ok(t) = SpectralTable::parse("fuzz.csv", &text) {
            // What parses is consistent and resamples or refuses cleanly.
            prop_assert!(t.columns.iter().all(|c| c.len() == t.wavelengths.len()));
            let _ = t.resampled(&specconv_colour::Grid::PAPER);
        }
    }

    #[test]
    fn damaged_models_never_panic(edits in prop::collection::vec(edit(), 1..6)) {
        let text = mutate(&Model::builtin().to_json(), &edits);
        if let Ok(m) = Model::from_json("fuzz.json", &text) {
            // A model that loads must uplift without panicking.
            let up = specconv_spectral::Uplifter::new(&m).unwrap();
            let mut r = vec![0.0; m.grid.len()];
            specconv_spectral::Method::uplift_f64(&up, &[0.2, 0.3, 0.1], &mut r);
        }
    }
}
