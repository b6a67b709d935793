//! Candidate rules for colours whose spectrum leaves [0, 1], measured side by side (issue 55,
//! decision 1; docs/hard-inputs.md, "Candidates for colours outside the solid"). Asserts
//! nothing; prints, for one candidate:
//!
//! - continuity: HSV hue ramps (S = 1, 0.75, 0.5; V = 0.5, 1, 1.5, 10) in ACEScg, Rec.2020 and
//!   linear sRGB, made XYZ with the D65 white OpenColorIO uses and rounded to float32; for
//!   neighbours whose inputs are within 0.05 CIEDE2000 under D65, the largest step between their
//!   spectra's colours under D65, A and F11, and how many steps exceed 0.5 (and between which
//!   kinds of colour: in range, projected inside the solid, outside it);
//! - distance: mean and worst CIEDE2000 (D65) between each outside colour of the Rec.2020 and
//!   ACEScg 17³ cubes and its spectrum's colour;
//! - exactness: the relative XYZ error of the colours projected inside the solid (wide-gamut
//!   cubes, linear sRGB 33³ cube);
//! - cost: wall time per colour, outside against projected inside, in the same run.
//!
//!     cargo run --release -p specconv-spectral --example outside_rules -- CANDIDATE [MU] [STEPS] [f64-w]
//!
//! CANDIDATE: `today` (the CIELAB search, then r₀ projected onto the colour reached with
//! penalty 10⁻⁹); `xyz` (one problem for every spectrum out of range, inside the solid or not:
//! min ½‖r − r₀‖² + ‖A·r − c‖²/(2μ), μ = MU·trace(A·Aᵀ): the nearest colour in XYZ, strictly
//! convex); `lab-at-c` (the same in the metric of CIELAB's Jacobian at c); `xyz-outside` (`xyz`
//! for outside colours only, the exact projection inside); `xyz-then-today` (the colour `xyz`
//! reaches, then today's projection onto it). w is rounded to float32 (a compact texel's u)
//! unless `f64-w` is given. MU defaults to 1e-9, STEPS (per ramp) to 20000.

use specconv_colour::lab::{ciede2000, xyz_to_lab, xyz_to_lab_jacobian};
use specconv_colour::rgb::{ACESCG, REC2020, SRGB};
use specconv_colour::solid::{Solid, Solve};
use specconv_colour::{Colorimetry, Grid, Illuminant};
use specconv_spectral::baselines::jakob_cache::TableCache;
use specconv_spectral::bounded::Bounded;
use specconv_spectral::method::MethodName;
use specconv_spectral::stack::{Stack, StackSpec};
use specconv_spectral::{Method, Model};
use std::time::Instant;

/// The default stack without its bound: r₀ as `convert` makes it.
struct Unbounded(Stack);

impl Method for Unbounded {
    fn name(&self) -> &str {
        self.0.method().name()
    }
    fn grid(&self) -> Grid {
        self.0.method().grid()
    }
    fn uplift_f64(&self, xyz: &[f64], out: &mut [f64]) {
        self.0.method().uplift_f64(xyz, out)
    }
    fn uplift_f32(&self, xyz: &[f32], out: &mut [f32]) {
        self.0.method().uplift_f32(xyz, out)
    }
    fn model_bytes(&self) -> usize {
        0
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Candidate {
    Today,
    Xyz,
    LabAtC,
    XyzOutside,
    XyzThenToday,
}

struct Setup {
    bounded: Bounded<Unbounded>,
    a: Colorimetry,
    candidate: Candidate,
    mu: f64,
    f32_w: bool,
}

impl Setup {
    /// The candidate's spectrum of `c` into `r`.
    fn spectrum(&self, c: [f64; 3], r: &mut [f64]) {
        self.bounded.inner().uplift_f64(&c, r);
        let in_range = r.iter().all(|v| (0.0..=1.0).contains(v));
        if self.candidate == Candidate::Today || self.bounded.is_white(c) || in_range {
            self.bounded.bound(c, r);
            return;
        }
        let r0 = r.to_vec();
        if self.candidate == Candidate::XyzOutside
            && self.bounded.solid().project_dual(c, &r0, r, 60).0 == Solve::Solved
        {
            return;
        }
        let j = match self.candidate {
            Candidate::LabAtC => xyz_to_lab_jacobian(c, self.a.white_xyz()).1,
            _ => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        };
        let apply = |v: [f64; 3]| j.map(|row| (0..3).map(|m| row[m] * v[m]).sum::<f64>());
        let mut rows: [Vec<f64>; 3] = Default::default();
        for i in 0..self.a.bands() {
            let col = apply([0, 1, 2].map(|m| self.a.weights[m][i]));
            (0..3).for_each(|k| rows[k].push(col[k]));
        }
        let solid = Solid::new(&rows);
        let (_, w) = solid.project_regularised(apply(c), &r0, r, self.mu, 200);
        solid.texel_form(&r0, self.round(w), r);
        if self.candidate == Candidate::XyzThenToday {
            let reached = self.a.xyz(r);
            let today = self.bounded.solid();
            let (_, w) = today.project_regularised(reached, &r0, r, 1e-9, 200);
            today.texel_form(&r0, self.round(w), r);
        }
    }

    fn round(&self, w: [f64; 3]) -> [f64; 3] {
        match self.f32_w {
            true => w.map(|v| f64::from(v as f32)),
            false => w,
        }
    }

    /// 0: the model's spectrum in range; 1: projected inside the solid; 2: outside.
    fn kind(&self, c: [f64; 3]) -> usize {
        let n = self.a.bands();
        let (mut r0, mut r) = (vec![0.0; n], vec![0.0; n]);
        self.bounded.inner().uplift_f64(&c, &mut r0);
        if r0.iter().all(|v| (0.0..=1.0).contains(v)) {
            return 0;
        }
        match self.bounded.solid().project_dual(c, &r0, &mut r, 60).0 {
            Solve::Solved => 1,
            _ => 2,
        }
    }
}

fn hsv(h: f64, s: f64, v: f64) -> [f64; 3] {
    let h6 = (h * 6.0).rem_euclid(6.0);
    let f = h6 - h6.floor();
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f)));
    match h6.floor() as i32 {
        0 => [v, t, p],
        1 => [q, v, p],
        2 => [p, v, t],
        3 => [p, q, v],
        4 => [t, p, v],
        _ => [v, p, q],
    }
}

fn times(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    m.map(|row| (0..3).map(|k| row[k] * v[k]).sum::<f64>())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let candidate = match args.get(1).map(String::as_str) {
        Some("today") => Candidate::Today,
        Some("xyz") => Candidate::Xyz,
        Some("lab-at-c") => Candidate::LabAtC,
        Some("xyz-outside") => Candidate::XyzOutside,
        Some("xyz-then-today") => Candidate::XyzThenToday,
        _ => panic!("a candidate: today, xyz, lab-at-c, xyz-outside, xyz-then-today"),
    };
    let mu: f64 = args.get(2).map_or(1e-9, |s| s.parse().expect("MU"));
    let steps: usize = args.get(3).map_or(20_000, |s| s.parse().expect("STEPS"));
    let f32_w = args.get(4).map(String::as_str) != Some("f64-w");
    let mut d = StackSpec::convert_default(MethodName::Otsu2018);
    d.bounded = false;
    let stack = Stack::build(&d, Model::builtin(), &TableCache::none()).unwrap();
    let a = stack.colorimetry().clone();
    let setup = Setup {
        bounded: Bounded::new(Unbounded(stack), a.clone()).unwrap(),
        a: a.clone(),
        candidate,
        mu,
        f32_w,
    };
    let lights: Vec<Colorimetry> = [Illuminant::D65, Illuminant::A, Illuminant::FL11]
        .into_iter()
        .map(|i| Colorimetry::new(a.grid, a.observer, i).unwrap())
        .collect();
    let lab = |l: &Colorimetry, r: &[f64]| xyz_to_lab(l.xyz(r), l.white_xyz());
    let d65 = SRGB.white_xyz();
    let mut r = vec![0.0; a.bands()];

    let (mut worst, mut over, mut kinds) = ([0.0f64; 3], 0, [[0usize; 3]; 3]);
    for (name, space) in [("ACEScg", ACESCG), ("Rec.2020", REC2020), ("sRGB", SRGB)] {
        let m = space.to_xyz(d65);
        for s in [1.0, 0.75, 0.5] {
            for v in [0.5, 1.0, 1.5, 10.0] {
                let (mut ramp_worst, mut ramp_over) = ([0.0f64; 3], 0);
                let mut prev: Option<([f64; 3], [[f64; 3]; 3], usize)> = None;
                for i in 0..=steps {
                    let rgb = hsv(i as f64 / steps as f64, s, v);
                    let c = times(&m, rgb).map(|v| f64::from(v as f32));
                    setup.spectrum(c, &mut r);
                    let labs = [0, 1, 2].map(|k| lab(&lights[k], &r));
                    let (input, kind) = (xyz_to_lab(c, lights[0].white_xyz()), setup.kind(c));
                    if let Some((p_input, p_labs, p_kind)) = prev {
                        if ciede2000(p_input, input) <= 0.05 {
                            let step = [0, 1, 2].map(|k| ciede2000(p_labs[k], labs[k]));
                            (0..3).for_each(|k| ramp_worst[k] = ramp_worst[k].max(step[k]));
                            if step.iter().any(|&s| s > 0.5) {
                                ramp_over += 1;
                                kinds[p_kind][kind] += 1;
                            }
                        }
                    }
                    prev = Some((input, labs, kind));
                }
                (0..3).for_each(|k| worst[k] = worst[k].max(ramp_worst[k]));
                over += ramp_over;
                if ramp_over > 0 {
                    println!(
                        "{name} S {s} V {v}: largest step D65 {:.2} A {:.2} F11 {:.2}, over 0.5: {ramp_over}",
                        ramp_worst[0], ramp_worst[1], ramp_worst[2]
                    );
                }
            }
        }
    }
    println!(
        "ramps ({steps} steps): largest step D65 {:.3} A {:.3} F11 {:.3}; steps over 0.5: {over}; \
         by kinds (in range, projected, outside; from → to): {kinds:?}",
        worst[0], worst[1], worst[2]
    );

    let cube = |space: specconv_colour::rgb::RgbSpace, k: usize| {
        let m = space.to_xyz(d65);
        let mut all = vec![];
        for i in 0..k * k * k {
            let rgb = [i / (k * k), i / k % k, i % k].map(|v| v as f64 / (k - 1) as f64);
            all.push(times(&m, rgb));
        }
        all
    };
    let wide: Vec<[f64; 3]> = [cube(REC2020, 17), cube(ACESCG, 17)].concat();
    let outside: Vec<[f64; 3]> = wide
        .iter()
        .copied()
        .filter(|&c| !setup.bounded.is_white(c) && setup.kind(c) == 2)
        .collect();
    let white = lights[0].white_xyz();
    let (mut sum, mut far) = (0.0, 0.0f64);
    for &c in &outside {
        setup.spectrum(c, &mut r);
        let de = ciede2000(xyz_to_lab(c, white), xyz_to_lab(a.xyz(&r), white));
        (sum, far) = (sum + de, far.max(de));
    }
    println!(
        "distance: {} outside colours, mean ΔE00 {:.4}, worst {far:.3}",
        outside.len(),
        sum / outside.len() as f64
    );
    let projected = |set: &[[f64; 3]]| -> Vec<[f64; 3]> {
        set.iter()
            .copied()
            .filter(|&c| !setup.bounded.is_white(c) && setup.kind(c) == 1)
            .collect()
    };
    let (wide_in, srgb_in) = (projected(&wide), projected(&cube(SRGB, 33)));
    for (name, set) in [("wide-gamut cubes", &wide_in), ("sRGB 33³", &srgb_in)] {
        let (mut sum, mut far, mut over) = (0.0, 0.0f64, 0);
        for &c in set.iter() {
            setup.spectrum(c, &mut r);
            let back = a.xyz(&r);
            let scale = c.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let e = (0..3).fold(0.0f64, |m, k| m.max((back[k] - c[k]).abs())) / scale;
            (sum, far, over) = (sum + e, far.max(e), over + usize::from(e > 1e-5));
        }
        println!(
            "exactness, {name}: {} projected inside, relative XYZ error mean {:.2e}, worst \
             {far:.2e}, over 1e-5: {over}",
            set.len(),
            sum / set.len() as f64
        );
    }
    let per_colour = |set: &[[f64; 3]], r: &mut [f64]| {
        let (start, mut k) = (Instant::now(), 0usize);
        while start.elapsed().as_secs_f64() < 0.5 {
            set.iter().for_each(|&c| setup.spectrum(c, r));
            k += set.len();
        }
        start.elapsed().as_nanos() as f64 / k as f64
    };
    let (t_out, t_in) = (per_colour(&outside, &mut r), per_colour(&wide_in, &mut r));
    println!(
        "cost (wall, ns a colour): outside {t_out:.0}, projected inside {t_in:.0}, ratio {:.1}",
        t_out / t_in
    );
}
