//! Design checks of the pressure loop against an independently written linear model of the
//! rig: the closed loop's poles over the precharge and pressure ranges.

use super::*;

type Poly = Vec<f64>; // coefficients, lowest power first

fn mul(a: &[f64], b: &[f64]) -> Poly {
    let mut r = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            r[i + j] += x * y;
        }
    }
    r
}

fn add(a: &[f64], b: &[f64]) -> Poly {
    let mut r = vec![0.0; a.len().max(b.len())];
    for (i, x) in a.iter().enumerate() {
        r[i] += x;
    }
    for (i, x) in b.iter().enumerate() {
        r[i] += x;
    }
    r
}

fn prod(fs: &[&[f64]]) -> Poly {
    fs.iter().fold(vec![1.0], |acc, f| mul(&acc, f))
}

#[derive(Clone, Copy, Debug)]
struct C64 {
    re: f64,
    im: f64,
}

impl C64 {
    fn add(self, o: C64) -> C64 {
        C64 {
            re: self.re + o.re,
            im: self.im + o.im,
        }
    }
    fn sub(self, o: C64) -> C64 {
        C64 {
            re: self.re - o.re,
            im: self.im - o.im,
        }
    }
    fn mul(self, o: C64) -> C64 {
        C64 {
            re: self.re * o.re - self.im * o.im,
            im: self.re * o.im + self.im * o.re,
        }
    }
    fn div(self, o: C64) -> C64 {
        let d = o.re * o.re + o.im * o.im;
        C64 {
            re: (self.re * o.re + self.im * o.im) / d,
            im: (self.im * o.re - self.re * o.im) / d,
        }
    }
    fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }
}

/// Roots of a real polynomial by the Durand–Kerner iteration (on a scaled variable).
fn roots(p: &[f64]) -> Vec<C64> {
    let mut p: Vec<f64> = p.to_vec();
    while p.last().is_some_and(|c| *c == 0.0) {
        p.pop();
    }
    let n = p.len() - 1;
    // Scale s = k·z so the coefficients are balanced: k = geometric spread of the roots.
    let k = (p[0].abs() / p[n].abs()).powf(1.0 / n as f64);
    let q: Vec<f64> = p
        .iter()
        .enumerate()
        .map(|(i, c)| c * k.powi(i as i32) / (p[n] * k.powi(n as i32)))
        .collect();
    let eval = |z: C64| {
        q.iter().rev().fold(C64 { re: 0.0, im: 0.0 }, |acc, c| {
            acc.mul(z).add(C64 { re: *c, im: 0.0 })
        })
    };
    let seed = C64 { re: 0.4, im: 0.9 };
    let mut z: Vec<C64> = (0..n)
        .map(|i| (0..i).fold(C64 { re: 1.0, im: 0.0 }, |a, _| a.mul(seed)))
        .collect();
    for _ in 0..5000 {
        let mut change = 0.0f64;
        for i in 0..n {
            let mut den = C64 { re: 1.0, im: 0.0 };
            for j in 0..n {
                if i != j {
                    den = den.mul(z[i].sub(z[j]));
                }
            }
            let step = eval(z[i]).div(den);
            z[i] = z[i].sub(step);
            change = change.max(step.abs() / z[i].abs().max(1e-12));
        }
        if change < 1e-14 {
            break;
        }
    }
    z.into_iter()
        .map(|r| C64 {
            re: r.re * k,
            im: r.im * k,
        })
        .collect()
}

/// Plant and inner-loop facts of the nominal rig, written out independently of `Config`.
struct Rig {
    precharge: f64,
}

const D_P: f64 = 1.5e-6; // m³/rev
const V_OIL: f64 = 450e-6;
const BETA: f64 = 6.5e8;
const V_0: f64 = 400e-6;
const N_GAS: f64 = 1.3;
const P_ATM: f64 = 101_325.0;
const G_LEAK: f64 = 3e-13;
const INERTANCE: f64 = 3.85e5; // kg/m⁴, plant model's absorber inlet
const R_INLET: f64 = 3e7; // Pa·s/m³
const J: f64 = 8.0e-4; // motor + pump
const B: f64 = 3.035e-4;
const K_T: f64 = 1.5 * 4.0 * 0.1827;
const W_CC: f64 = 1100.0; // current loop
const KP_S: f64 = 0.14;
const KI_S: f64 = 7.0;
const BA: f64 = 0.013;
const TAU_SPEED: f64 = 0.5e-3; // speed measurement window/2 + hold/2
const TAU_P: f64 = 1.5e-3; // boxcar/2 + hold/2 + pressure-loop hold

impl Rig {
    /// Gas capacitance from the polytropic law at gauge pressure p (0 below precharge),
    /// by differentiating V_g(p) numerically — a different route than the closed form.
    fn c_acc(&self, p: f64) -> f64 {
        if p <= self.precharge {
            return 0.0;
        }
        let vg = |p: f64| V_0 * ((self.precharge + P_ATM) / (p + P_ATM)).powf(1.0 / N_GAS);
        let h = 1.0;
        (vg(p - h) - vg(p + h)) / (2.0 * h)
    }

    /// Closed-loop characteristic polynomial with the pressure PI gains `kp`, `ki` and
    /// feedback filter `wf`.
    fn characteristic(&self, p: f64, kp: f64, ki: f64, wf: f64) -> Poly {
        let kq = D_P / (2.0 * std::f64::consts::PI);
        let c1 = V_OIL / BETA;
        let ca = self.c_acc(p);
        // Absorber branch admittance Ny/Dy = Ca·s / (I·Ca·s² + R·Ca·s + 1).
        let (ny, dy): (Poly, Poly) = if ca > 0.0 {
            (vec![0.0, ca], vec![1.0, R_INLET * ca, INERTANCE * ca])
        } else {
            (vec![0.0], vec![1.0])
        };
        let dz = add(&mul(&[G_LEAK, c1], &dy), &ny);
        let dm = vec![B, J];
        let dgi = vec![W_CC, 1.0];
        let s = vec![0.0, 1.0];
        let pade = |tau: f64| (vec![1.0, -tau / 2.0], vec![1.0, tau / 2.0]);
        let (ndw, ddw) = pade(TAU_SPEED);
        let (ndp, ddp) = pade(TAU_P);
        let sf = vec![wf, 1.0];
        let t0 = prod(&[&dm, &dgi, &s, &ddw, &dz, &ddp, &sf, &s]);
        let t1 = prod(&[&[0.0, K_T * W_CC * (KP_S + BA)], &ndw, &dz, &ddp, &sf, &s]);
        let t1 = add(
            &t1,
            &prod(&[&[K_T * W_CC * KI_S], &ndw, &dz, &ddp, &sf, &s]),
        );
        let t2 = prod(&[&[kq * kq], &dy, &dgi, &s, &ddw, &ddp, &sf, &s]);
        let t3 = prod(&[
            &[K_T * W_CC * wf * kq],
            &[KI_S, KP_S],
            &[ki, kp],
            &ndp,
            &dy,
            &ddw,
        ]);
        add(&add(&t0, &t1), &add(&t2, &t3))
    }

    /// Chamber resonance with the absorber's oil column. [rad/s]
    fn chamber_resonance(&self, p: f64) -> Option<f64> {
        let ca = self.c_acc(p);
        let c1 = V_OIL / BETA;
        (ca > 0.0).then(|| ((c1 + ca) / (INERTANCE * c1 * ca)).sqrt())
    }
}

#[test]
fn capacitance_matches_the_gas_law() {
    let mut cfg = Config::nominal();
    for p0 in [2e6, 5e6, 13e6] {
        cfg.hydraulics.absorber_precharge_pa = p0 as f32;
        let rig = Rig { precharge: p0 };
        for p in [1e6, 4e6, 8e6, 14e6] {
            let want = V_OIL / BETA + rig.c_acc(p);
            let got = capacitance(&cfg.hydraulics, p as f32) as f64;
            assert!(
                (got - want).abs() < 2e-3 * want,
                "p0 {p0} p {p}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn closed_loop_poles_are_damped_over_precharges_and_pressures() {
    let mut worst = f64::MAX;
    let mut worst_res = f64::MAX;
    let mut slowest = f64::MAX;
    for p0_mpa in [2.0, 3.0, 4.0, 5.0, 7.0, 10.0, 13.0] {
        let mut cfg = Config::nominal();
        cfg.hydraulics.absorber_precharge_pa = p0_mpa as f32 * 1e6;
        let pl = PressureLoop::new(&cfg);
        let rig = Rig {
            precharge: p0_mpa * 1e6,
        };
        for p_mpa in [
            1.0, 1.9, 2.1, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 12.9, 13.1, 14.0, 15.0,
        ] {
            let p = p_mpa * 1e6;
            let g = pl.gains_at(p as f32);
            let poly = rig.characteristic(
                p,
                g.kp as f64,
                g.ki as f64,
                cfg.pressure.feedback_filter_rad_s as f64,
            );
            let rs = roots(&poly);
            // The roots must be roots: residual check relative to the polynomial's scale.
            for r in &rs {
                assert!(
                    r.re < 0.0,
                    "unstable pole {r:?} at p0 {p0_mpa} MPa, p {p_mpa} MPa"
                );
            }
            let res = rig.chamber_resonance(p);
            for r in &rs {
                let zeta = -r.re / r.abs();
                let is_resonance =
                    res.is_some_and(|w| (r.abs() - w).abs() < 0.35 * w) && r.im.abs() > 0.0;
                if is_resonance {
                    // Open-loop damping of the chamber/oil-column resonance: the
                    // denominator s² + (R/I)·s + ω_r² of the chamber impedance.
                    let zeta_ol = R_INLET / INERTANCE / (2.0 * res.unwrap_or(1.0));
                    worst_res = worst_res.min(zeta / zeta_ol);
                    assert!(
                        zeta >= PROMISED_RESONANCE_DAMPING_RATIO * zeta_ol,
                        "resonance pole {r:?} ζ {zeta:.4} (open loop {zeta_ol:.4}) at p0 {p0_mpa} p {p_mpa}"
                    );
                } else {
                    worst = worst.min(zeta);
                    assert!(
                        zeta >= PROMISED_DAMPING,
                        "pole {r:?} ζ {zeta:.3} at p0 {p0_mpa} MPa, p {p_mpa} MPa"
                    );
                }
                if r.abs() < 200.0 {
                    slowest = slowest.min(-r.re);
                }
            }
        }
    }
    eprintln!("worst ζ {worst:.3}, worst resonance ζ/ζ_open-loop {worst_res:.3}, slowest decay {slowest:.2} 1/s");
}

#[test]
fn root_finder_finds_known_roots() {
    // (s + 1)(s + 2)(s² + 2s + 5): roots −1, −2, −1 ± 2j.
    let p = prod(&[&[1.0, 1.0], &[2.0, 1.0], &[5.0, 2.0, 1.0]]);
    let mut rs = roots(&p);
    rs.sort_by(|a, b| {
        a.im.partial_cmp(&b.im)
            .unwrap()
            .then(a.re.partial_cmp(&b.re).unwrap())
    });
    let want = [(-1.0, -2.0), (-2.0, 0.0), (-1.0, 0.0), (-1.0, 2.0)];
    for (r, (re, im)) in rs.iter().zip(want) {
        assert!(
            (r.re - re).abs() < 1e-9 && (r.im - im).abs() < 1e-9,
            "{r:?}"
        );
    }
}

#[test]
fn unscheduled_gains_would_fail_the_check() {
    // The check can fail: gains sized for the absorber's capacitance (p0 = 2 MPa at 2.1 MPa)
    // applied where only the oil is compressed (1 MPa) make the loop unstable or poorly
    // damped.
    let mut cfg = Config::nominal();
    cfg.hydraulics.absorber_precharge_pa = 2e6;
    let pl = PressureLoop::new(&cfg);
    let g = pl.gains_at(2.1e6);
    let rig = Rig { precharge: 2e6 };
    let rs = roots(&rig.characteristic(1e6, g.kp as f64, g.ki as f64, 150.0));
    let worst = rs.iter().map(|r| -r.re / r.abs()).fold(f64::MAX, f64::min);
    assert!(worst < PROMISED_DAMPING, "worst ζ {worst}");
}
