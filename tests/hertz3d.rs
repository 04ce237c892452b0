//! Hertz in 3D (issue 13): a rigid sphere pressed into an elastic quarter block
//! (src/harness/hertz3d.rs), against the closed form `a = (3 P R / (4 E*))^(1/3)`,
//! `p0 = 3 P / (2 pi a^2)`: the contact radius lies between the outermost closed node and the
//! next open one, and the errors of the moment radius and of the peak pressure fall under
//! refinement to a few percent.

use contact_patch::harness::hertz3d::{level, TARGET_RADIUS};

#[test]
fn contact_radius_and_peak_pressure_converge_to_hertz() {
    // the report adds a / 8 (`contact-patch hertz-3d`)
    let sizes = [
        TARGET_RADIUS / 2.0,
        TARGET_RADIUS / 4.0,
        TARGET_RADIUS / 6.0,
    ];
    let levels: Vec<_> = sizes.iter().map(|&h| level(h).unwrap()).collect();
    for l in &levels {
        eprintln!(
            "h {:.4} dofs {} P {:.5e} a {:.5} bracket [{:.5}, {:.5}] a_m {:.5} ({:+.2e}) p0 {:.4} nodal {:.4} peak {:.4} ({:+.2e}, to p0 {:+.2e}) its {}",
            l.h, l.dofs, l.load, l.hertz_radius, l.closed_radius, l.open_radius,
            l.moment_radius, l.moment_radius_error, l.hertz_peak, l.hertz_nodal_peak, l.peak, l.peak_error,
            l.peak_error_to_p0, l.active_set_iterations
        );
        assert!(
            l.closed_radius <= l.hertz_radius && l.hertz_radius <= l.open_radius,
            "h = {}: Hertz's a = {} outside [{}, {}]",
            l.h,
            l.hertz_radius,
            l.closed_radius,
            l.open_radius
        );
    }
    for pair in levels.windows(2) {
        let (coarse, fine) = (&pair[0], &pair[1]);
        assert!(
            fine.moment_radius_error.abs() < coarse.moment_radius_error.abs(),
            "the radius error does not fall: {} -> {}",
            coarse.moment_radius_error,
            fine.moment_radius_error
        );
        assert!(
            fine.peak_error.abs() < coarse.peak_error.abs(),
            "the peak error does not fall: {} -> {}",
            coarse.peak_error,
            fine.peak_error
        );
    }
    let finest = levels.last().unwrap();
    assert!(
        finest.moment_radius_error.abs() < 0.03,
        "{}",
        finest.moment_radius_error
    );
    assert!(finest.peak_error.abs() < 0.03, "{}", finest.peak_error);
}
