//! The contact law against docs/MODEL.md §2: values at chosen points, continuity of F and dF/dξ
//! across each band edge, and the identities between the paper's constants (§4).
#![allow(non_snake_case)]

mod common;

use common::{F, PAPER};
use gear_rattle::physics::{ContactLaw, GearParams, Region};

fn law(epsilon: f64) -> ContactLaw {
    ContactLaw::new(&GearParams {
        epsilon,
        ..GearParams::paper()
    })
}

/// The crate's force with the region that contains ξ.
fn force(law: &ContactLaw, xi: f64, xi_dot: f64) -> f64 {
    law.force(law.classify(xi), xi, xi_dot).total()
}

#[test]
fn values_at_chosen_points_match_model_md() {
    let law = law(PAPER.epsilon);
    let g = PAPER.G;
    let points = [
        -5e-6,
        -2e-6,
        -1e-6,
        -0.75e-6,
        -0.5e-6,
        -0.1e-6,
        0.0,
        1e-6,
        g / 2.0,
        g,
        g + 0.3e-6,
        g + 0.5e-6,
        g + 1e-6,
        g + 4e-6,
    ];
    for xi in points {
        for xi_dot in [0.0, 0.05, -0.2] {
            let expected = F(&PAPER, xi, xi_dot);
            let got = force(&law, xi, xi_dot);
            assert!(
                (got - expected).abs() <= 1e-12 * expected.abs().max(1e-9),
                "xi = {xi:e}, xi' = {xi_dot}: {got} vs docs/MODEL.md {expected}"
            );
        }
    }
    // A hand check: full contact on F+ at ξ = −2 µm, at rest:
    // 3e6 · (−2e-6) · (2/25)^(1/3) = −6 · 0.430887 = −2.58532 N.
    assert!((force(&law, -2e-6, 0.0) + 2.585_32).abs() < 1e-5);
    // Middle of the F− band: s = ½, δ = 0.5 µm.
    let half = 0.5 * 3e6 * 0.5e-6 * (0.5f64 / 25.0).cbrt();
    assert!((force(&law, g + 0.5e-6, 0.0) - half).abs() < 1e-12);
}

/// F and dF/dξ are continuous at ξ = −ε, 0, G, G+ε: each region's formula, evaluated on the
/// edge from both sides, gives the same value and slope.
#[test]
fn force_and_its_slope_are_continuous_across_band_edges() {
    let law = law(PAPER.epsilon);
    let (e, g) = (PAPER.epsilon, PAPER.G);
    let edges = [
        (-e, Region::ContactPlus, Region::BandPlus),
        (0.0, Region::BandPlus, Region::Gap),
        (g, Region::Gap, Region::BandMinus),
        (g + e, Region::BandMinus, Region::ContactMinus),
    ];
    let h = 1e-12;
    for (edge, below, above) in edges {
        for xi_dot in [0.0, 0.03] {
            let f = |r: Region, x: f64| law.force(r, x, xi_dot).total();
            let (fb, fa) = (f(below, edge), f(above, edge));
            assert!((fb - fa).abs() < 1e-12, "F jumps at {edge:e}: {fb} vs {fa}");
            // One-sided slopes, each from its own side.
            let slope_below = (f(below, edge) - f(below, edge - h)) / h;
            let slope_above = (f(above, edge + h) - f(above, edge)) / h;
            let scale = PAPER.K_star;
            assert!(
                (slope_below - slope_above).abs() < 1e-3 * scale,
                "dF/dxi jumps at {edge:e}: {slope_below} vs {slope_above}"
            );
        }
    }
}

#[test]
fn without_a_band_the_force_is_continuous_at_the_gap_edges() {
    let law = law(0.0);
    for edge in [0.0, PAPER.G] {
        assert_eq!(force(&law, edge, 0.0), 0.0);
        assert!(force(&law, edge - 1e-15, 0.0).abs() < 1e-9);
        assert!(force(&law, edge + 1e-15, 0.0).abs() < 1e-9);
    }
    // No smoothing: at −1 µm the full force acts.
    let full = -3e6 * 1e-6 * (1.0f64 / 25.0).cbrt();
    assert!((force(&law, -1e-6, 0.0) - full).abs() < 1e-12);
}

/// K* δ |δ/G|^(α−1) = K_LM δ |δ|^(α−1) with K_LM = K*/G^(α−1), and the paper's numbers:
/// K_LM = 1.03e8 N/m^(4/3), C*_LM = 0.04, C* = 78 1/s (docs/MODEL.md §4).
#[test]
fn paper_constants_and_the_k_lm_identity() {
    let p = GearParams::paper();
    let law = law(p.epsilon);
    let K_LM = p.K_star / p.G.powf(p.alpha - 1.0);
    assert!((K_LM / 1.03e8 - 1.0).abs() < 0.005, "K_LM = {K_LM:e}");
    for delta in [-8e-6, -2e-6, -1.5e-6] {
        let via_k_lm = K_LM * delta * delta.abs().powf(p.alpha - 1.0);
        let got = law.force(Region::ContactPlus, delta, 0.0).total();
        assert!(
            (got - via_k_lm).abs() < 1e-12 * got.abs(),
            "{got} vs {via_k_lm}"
        );
    }
    let C_LM_star = p.C_LM / (2.0 * (p.K_star * p.I_L / (p.r_L * p.r_L)).sqrt());
    assert!((C_LM_star - 0.04).abs() < 0.0005, "C*_LM = {C_LM_star}");
    assert!((p.C / p.I_L - 78.0).abs() < 0.2, "C* = {}", p.C / p.I_L);
}
