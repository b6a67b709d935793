//! The paper's Table 1 (dataset I, Munsell matte), reproduced from ../shared.

use specconv_evaluation::eval;
use specconv_spectral::{train, Uplifter};
use specconv_testkit::*;

fn table1(clusters: usize) -> eval::Statistics {
    let a = paper();
    let set = set(MUNSELL, &a.grid);
    let model = train(&set, &a, &paper_options(clusters)).unwrap();
    assert_eq!(model.leaves.len(), clusters);
    let up = Uplifter::new(&model).unwrap();
    eval::summarise(&eval::evaluate(
        &a,
        &up,
        &set.spectra,
        &eval::Viewing::none(),
    ))
}

#[test]
fn ours_with_eight_clusters_matches_table_1() {
    let s = table1(8);
    eprintln!("8 clusters: {s:?}");
    assert_eq!(s.count, 1269);
    assert!(
        (s.delta_e.mean - 0.0138).abs() <= 0.0007,
        "mean {}",
        s.delta_e.mean
    );
    assert!(
        (s.delta_e.median - 0.0053).abs() <= 0.0003,
        "median {}",
        s.delta_e.median
    );
    assert!(s.roundtrip_max <= 1e-9, "round trip {}", s.roundtrip_max);
}

#[test]
fn pca_only_matches_table_1() {
    let s = table1(1);
    eprintln!("1 cluster: {s:?}");
    assert!(
        (s.delta_e.mean - 0.0388).abs() <= 0.0010,
        "mean {}",
        s.delta_e.mean
    );
    assert!(s.roundtrip_max <= 1e-9, "round trip {}", s.roundtrip_max);
}
