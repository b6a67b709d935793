//! Cost of bounding colours outside the object-colour solid against colours inside it, in one
//! run (issue 45, item 16; docs/performance.md): N random XYZ colours, uniform in [0, 1.2)³
//! (a seeded stream: the same colours every run), each uplifted in f64 once; then, per colour,
//! the best of 5 timed passes of `Bounded::bound` over each kind (already in range, projected,
//! outside the solid) (the thread's CPU time where Linux reports it, so that a loaded machine's other work is
//! not counted; wall time elsewhere). Prints each kind's time, the ratios of outside to
//! in-solid, and where an outside colour's time goes: the certificate (the projection that fails), the nearest colour in
//! CIELAB, and the rest (the regularised projection onto it, into the texel form).
//!
//!     cargo run -j 1 -p specconv-spectral --example solid_cost [N]
//!     cargo run -j 1 -p specconv-spectral --example solid_cost -- [N] outside   # for `perf`

use specconv_spectral::bounded::{nearest, Bounded, Outcome};
use specconv_spectral::{Method, Model, Uplifter};
use specconv_testkit::SplitMix;
use std::hint::black_box;
use std::time::Instant;

type Set = Vec<([f64; 3], Vec<f64>)>;

/// This thread's CPU time in ns where Linux reports it (/proc/thread-self/schedstat), so that
/// other processes on a loaded machine are not counted; else the wall time since `epoch`.
fn clock(epoch: Instant) -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or_else(|| epoch.elapsed().as_secs_f64() * 1e9)
}

/// Best of 5 timed passes over `set`, in ns per colour ([`clock`]); each pass goes over the set
/// as many times as 50 ms of wall time take, since the kernel updates a thread's CPU time at
/// its ticks only.
fn per_colour(set: &Set, mut f: impl FnMut([f64; 3], &[f64])) -> f64 {
    let epoch = Instant::now();
    let mut repeats = 0usize;
    while epoch.elapsed().as_secs_f64() < 0.05 || repeats == 0 {
        set.iter().for_each(|(c, r0)| f(black_box(*c), r0));
        repeats += 1;
    }
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let start = clock(epoch);
        for _ in 0..repeats {
            set.iter().for_each(|(c, r0)| f(black_box(*c), r0));
        }
        best = best.min((clock(epoch) - start) / (repeats * set.len()).max(1) as f64);
    }
    best
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let count: usize = args.get(1).map_or(5_000, |s| s.parse().expect("a count"));
    let model = Model::builtin();
    let a = model.colorimetry().unwrap();
    let bounded = Bounded::new(Uplifter::new(model).unwrap(), a.clone()).unwrap();
    let n = a.bands();
    let mut rng = SplitMix(4516);
    let mut r = vec![0.0; n];
    let mut kinds: [Set; 3] = Default::default();
    for _ in 0..count {
        let c = [
            rng.uniform() * 1.2,
            rng.uniform() * 1.2,
            rng.uniform() * 1.2,
        ];
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
    let inside = (t[0] * kinds[0].len() as f64 + t[1] * kinds[1].len() as f64)
        / (kinds[0].len() + kinds[1].len()).max(1) as f64;
    println!(
        "{count} uniform XYZ in [0, 1.2)³, {} ns per colour: in range {} ({:.0}), projected {} \
         ({:.0}), in the solid on average {inside:.0}; outside {} ({:.0})",
        if std::path::Path::new("/proc/thread-self/schedstat").exists() {
            "CPU"
        } else {
            "wall"
        },
        kinds[0].len(),
        t[0],
        kinds[1].len(),
        t[1],
        kinds[2].len(),
        t[2],
    );
    println!(
        "outside / in the solid: {:.1}; outside / projected: {:.1}",
        t[2] / inside,
        t[2] / t[1],
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
         the regularised projection into the texel form {:.0} ns",
        t[2] - t_cert - t_near,
    );
}
