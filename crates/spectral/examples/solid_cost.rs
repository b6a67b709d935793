//! Cost of bounding colours outside the object-colour solid against colours inside it, in one
//! run (issue 45, item 16; docs/performance.md): N random XYZ colours, uniform in [0, 1.2)³
//! (a seeded stream: the same colours every run), each uplifted in f64 once; then, per colour,
//! the best of 5 timed passes of `Bounded::bound` over each kind (already in range, projected,
//! outside the solid), and of `Bounded::bound_reference` (the method before) over the outside
//! ones. Prints each kind's time, the ratios of outside to in-solid, and where an outside
//! colour's time goes: the certificate (the projection that fails), the nearest colour in
//! CIELAB, and the rest (the pull into the texel form).
//!
//!     cargo run -j 1 -p specconv-spectral --example solid_cost [N]
//!     cargo run -j 1 -p specconv-spectral --example solid_cost -- [N] outside   # for `perf`

use specconv_spectral::bounded::{nearest, Bounded, Outcome};
use specconv_spectral::{Method, Model, Uplifter};
use std::hint::black_box;
use std::time::Instant;

/// splitmix64 as a draw in [0, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

type Set = Vec<([f64; 3], Vec<f64>)>;

/// Best of 5 passes over `set`, in ns per colour.
fn per_colour(set: &Set, mut f: impl FnMut([f64; 3], &[f64])) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let start = Instant::now();
        for (c, r0) in set {
            f(black_box(*c), r0);
        }
        best = best.min(start.elapsed().as_secs_f64() / set.len().max(1) as f64);
    }
    best * 1e9
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let count: usize = args.get(1).map_or(5_000, |s| s.parse().expect("a count"));
    let model = Model::builtin();
    let a = model.colorimetry().unwrap();
    let bounded = Bounded::new(Uplifter::new(model).unwrap(), a.clone()).unwrap();
    let n = a.bands();
    let mut rng = Rng(4516);
    let mut r = vec![0.0; n];
    let mut kinds: [Set; 3] = Default::default();
    for _ in 0..count {
        let c = [rng.next() * 1.2, rng.next() * 1.2, rng.next() * 1.2];
        bounded.inner().uplift_f64(&c, &mut r);
        let r0 = r.clone();
        let k = match bounded.bound(c, &mut r) {
            Outcome::InRange => 0,
            Outcome::Projected => 1,
            Outcome::Outside { .. } => 2,
            Outcome::NotFinite => unreachable!("finite colours"),
        };
        kinds[k].push((c, r0));
    }
    let mut bound = |c: [f64; 3], r0: &[f64]| {
        r.copy_from_slice(r0);
        black_box(bounded.bound(c, &mut r));
    };
    if args.get(2).map(String::as_str) == Some("outside") {
        per_colour(&kinds[2], &mut bound);
        return;
    }
    let t = [0, 1, 2].map(|k| per_colour(&kinds[k], &mut bound));
    let mut s = vec![0.0; n];
    let t_ref = per_colour(&kinds[2], |c, r0| {
        s.copy_from_slice(r0);
        black_box(bounded.bound_reference(c, &mut s));
    });
    let inside = (t[0] * kinds[0].len() as f64 + t[1] * kinds[1].len() as f64)
        / (kinds[0].len() + kinds[1].len()).max(1) as f64;
    println!(
        "{count} uniform XYZ in [0, 1.2)³, ns per colour: in range {} ({:.0}), projected {} \
         ({:.0}), in the solid on average {inside:.0}; outside {} ({:.0}, before {t_ref:.0}: \
         {:.2}×)",
        kinds[0].len(),
        t[0],
        kinds[1].len(),
        t[1],
        kinds[2].len(),
        t[2],
        t_ref / t[2]
    );
    println!(
        "outside / in the solid: {:.1} (before {:.1}); outside / projected: {:.1} (before {:.1})",
        t[2] / inside,
        t_ref / inside,
        t[2] / t[1],
        t_ref / t[1]
    );
    let (solid, white) = (bounded.solid(), a.white_xyz());
    let t_cert = per_colour(&kinds[2], |c, r0| {
        black_box(solid.project_dual(c, r0, &mut s, 60));
    });
    let t_near = per_colour(&kinds[2], |c, r0| {
        black_box(nearest::nearest_lab(solid, white, c, r0, &mut s));
    });
    println!(
        "an outside colour's time: certificate {t_cert:.0} ns, nearest in CIELAB {t_near:.0} ns, \
         the pull into the texel form {:.0} ns (before {:.0} ns)",
        t[2] - t_cert - t_near,
        t_ref - t_cert - t_near
    );
}
