//! The ironing problem at finite strain (`contact-patch ironing`, `src/harness/ironing.rs`):
//! properties that hold independently of the numbers the report prints. Every discretization
//! runs the whole path on every mesh; at every accepted load step the contact force on the die
//! balances the reaction at its driven top (Newton's equilibrium, to the solver's tolerance);
//! the slab pushes the die up; the differences of the forces between successive refinements
//! shrink (convergence under refinement, the reference of a frictionless ironing problem
//! whose published curves are frictional); on the finest mesh, Newton with Lagrange rows keeps
//! `r_k+1 / r_k^2` bounded (<= 1e3) over the iterations within a settled active set, where the
//! problem is smooth; over every pair of iterations the ratio is a hundred times larger, as
//! rows open and close at the die's edges.
use contact_patch::harness::ironing::{self, entries, LEVELS, PRESS_STEPS, SLIDE, SLIDE_STEPS};

#[test]
fn the_ironing_problem_runs_balances_converges_under_refinement_and_quadratically() {
    let studies = ironing::study();
    assert_eq!(studies.len(), entries().len());
    for st in &studies {
        assert_eq!(st.runs.len(), LEVELS.len());
        for (l, r) in st.runs.iter().enumerate() {
            println!(
                "{} level {l}: {} (mean F_y {:.6}, F_y {:?}, F_x {:?}, balance {:.1e}, r_k+1/r_k^2 {:.2e} over {} pairs, cuts {})",
                st.label,
                r.outcome,
                r.mean_vertical,
                r.vertical,
                r.horizontal,
                r.balance,
                r.quadratic_ratio,
                r.quadratic_pairs,
                r.cuts
            );
        }
        for d in &st.differences {
            println!(
                "{} levels {} -> {}: F_y {:.3e}, F_x {:.3e} over {} steps",
                st.label,
                d.coarse,
                d.coarse + 1,
                d.vertical,
                d.horizontal,
                d.compared
            );
        }
    }
    for st in &studies {
        for r in &st.runs {
            assert_eq!(r.outcome, "ran", "{}", st.label);
            // the whole path, every accepted step in balance with the driven support
            assert!(r.path.len() >= PRESS_STEPS + SLIDE_STEPS);
            assert!((r.path.last().unwrap().slide - SLIDE).abs() < 1e-12);
            assert!(r.balance < 1e-9, "{}: {}", st.label, r.balance);
            assert!(
                r.mean_vertical > 0.0,
                "{}: the slab pushes the die up",
                st.label
            );
            assert!(
                r.quadratic_pairs >= SLIDE_STEPS,
                "{}: {}",
                st.label,
                r.quadratic_pairs
            );
        }
        // Newton's rate on the finest mesh: within a settled active set the ratio
        // r_k+1 / r_k^2 stays bounded (measured 6.2e2 for node-to-surface, 4.5e1 for mortar),
        // far below its value over every pair (1e5: the rows that open and close at the die's
        // edges at nearly every step make those iterations semi-smooth)
        let finest = st.runs.last().unwrap();
        assert!(finest.settled_quadratic_pairs >= 3, "{}", st.label);
        assert!(
            finest.settled_quadratic_ratio <= 1e3,
            "{}: {}",
            st.label,
            finest.settled_quadratic_ratio
        );
        assert!(
            finest.settled_quadratic_ratio < 1e-2 * finest.quadratic_ratio,
            "{}",
            st.label
        );
        // the forces converge under refinement: the differences of successive levels shrink
        assert_eq!(st.differences.len(), LEVELS.len() - 1, "{}", st.label);
        for d in &st.differences {
            assert!(d.compared >= PRESS_STEPS + SLIDE_STEPS, "{}", st.label);
        }
        let (first, second) = (&st.differences[0], &st.differences[1]);
        assert!(
            second.vertical < first.vertical,
            "{}: {} then {}",
            st.label,
            first.vertical,
            second.vertical
        );
        assert!(
            second.horizontal < first.horizontal,
            "{}: {} then {}",
            st.label,
            first.horizontal,
            second.horizontal
        );
    }
}
