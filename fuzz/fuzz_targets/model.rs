//! The model reader on any bytes: an error or a model that validated, and a model that loads
//! uplifts any colour without panicking, to a finite spectrum where the colour is finite.
#![no_main]

use libfuzzer_sys::fuzz_target;
use specconv_spectral::{Method, Model, Uplifter};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(m) = Model::from_json("fuzz.json", text) {
        let up = Uplifter::new(&m).expect("a validated model prepares");
        let mut r = vec![0.0; m.grid.len()];
        for c in [
            [0.2, 0.3, 0.1],
            [0.0; 3],
            [-1.0, 2.0, 1e30],
            [1e-9, 1e-9, 0.0],
        ] {
            up.uplift_f64(&c, &mut r);
            assert!(r.iter().all(|v| v.is_finite()), "{c:?}: {r:?}");
        }
    }
});
