//! The CSV reader on any bytes: an error or a consistent table, never a panic; what parses
//! resamples onto the paper's grid or refuses cleanly.
#![no_main]

use libfuzzer_sys::fuzz_target;
use specconv_colour::{Grid, SpectralTable};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(t) = SpectralTable::parse("fuzz.csv", text) {
        assert!(t.columns.iter().all(|c| c.len() == t.wavelengths.len()));
        assert_eq!(t.columns.len(), t.names.len());
        if let Ok(spectra) = t.resampled(&Grid::PAPER) {
            assert!(spectra.iter().all(|s| s.len() == Grid::PAPER.len()));
        }
    }
});
