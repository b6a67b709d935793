//! The baselines on the paper's dataset I (Table 1), and their round trips.

mod common;

use common::*;
use spectral::eval;
use spectral::methods::{Meng2015, Smits1999};
use spectral::Method;

fn table1(m: &dyn Method) -> eval::Summary {
    let a = paper();
    let s = set(MUNSELL, &a.grid);
    let sum = eval::summarise(&eval::evaluate(&a, m, &s.spectra));
    eprintln!(
        "{}: mean {:.4} median {:.4} max {:.4}; round trip {:.1e}, ΔE00 {:.2e}; in [0,1] {:.3}",
        m.name(),
        sum.delta_e.mean,
        sum.delta_e.median,
        sum.delta_e.max,
        sum.roundtrip_max,
        sum.roundtrip_de2000_max,
        sum.in_unit_range
    );
    sum
}

/// The paper reports 0.1904 / 0.0819 / 1.8439 for its Smits. An exact re-implementation, from
/// Smits' published basis in linear Rec. 709 RGB with the colorimetry's white (E here), lands
/// lower; see the README for why.
#[test]
fn smits1999_on_dataset_i() {
    let s = table1(&Smits1999::new(&paper()).unwrap());
    // Smits' basis is not exactly metameric to the RGB primaries: colours do not round-trip.
    assert!(s.roundtrip_de2000_max > 1.0);
    assert!((s.delta_e.mean - 0.1480).abs() < 5e-4, "{}", s.delta_e.mean);
    assert!(
        (s.delta_e.median - 0.0639).abs() < 5e-4,
        "{}",
        s.delta_e.median
    );
    assert!((s.delta_e.max - 1.1662).abs() < 5e-4, "{}", s.delta_e.max);
}

/// The paper reports 0.1633 / 0.0710 / 1.1410 for Meng et al.
#[test]
fn meng2015_on_dataset_i() {
    let a = paper();
    let s = table1(&Meng2015::new(&a, false).unwrap());
    assert!(
        s.roundtrip_max < 1e-12,
        "the smoothest spectrum has the colour exactly"
    );
    let b = table1(&Meng2015::new(&a, true).unwrap());
    assert!(b.roundtrip_max < 1e-10);
    assert!(b.in_unit_range > s.in_unit_range);
    assert!(
        b.in_unit_range == 1.0,
        "every Munsell chip's colour has a spectrum in [0, 1]"
    );
    for (got, want) in [
        (s.delta_e.mean, 0.1295),
        (s.delta_e.median, 0.0492),
        (s.delta_e.max, 1.1225),
        (b.delta_e.mean, 0.1289),
    ] {
        assert!((got - want).abs() < 5e-4, "{got} vs {want}");
    }
}
