//! Mesh convergence on Timoshenko & Goodier's cantilever (cases/convergence/): the relative L2
//! displacement error must fall like h^2 for the linear elements (Q4, T3) and h^3 for the
//! quadratic ones (Q9, T6). The error must fall at every refinement, and the observed rate
//! between the two finest meshes must be at least the theoretical order minus 0.15 and below the
//! order plus 0.7 (a rate a whole order too high would mean the test problem is too easy to
//! tell the elements apart).
//!
//! Measured (`cargo test --release --test convergence -- --nocapture`): Q4 1.99, T3 1.93,
//! Q9 3.09, T6 3.58. T6 on this structured diagonal mesh is pre-asymptotically faster than h^3;
//! refining further (8x, 16x, 32x the base mesh) its rate falls to 3.39 and then 3.17.

use contact_patch::io::scene::{Breaks, MeshSpec, UniformBreaks};
use contact_patch::model::{parse, Model};
use contact_patch::post::relative_l2_displacement_error;
use contact_patch::solver::solve_static;

fn errors(element: &str, levels: &[usize]) -> Vec<(f64, f64)> {
    let path = format!(
        "{}/cases/convergence/cantilever-{element}.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap();
    let base = parse(&text, &path).unwrap();
    levels
        .iter()
        .map(|&k| {
            let mut case = base.clone();
            let MeshSpec::Block(block) = &mut case.bodies[0].mesh else {
                panic!("a block mesh")
            };
            let refine = |b: &Breaks| match b {
                Breaks::Uniform(u) => Breaks::Uniform(UniformBreaks {
                    divisions: u.divisions * k,
                    ..u.clone()
                }),
                Breaks::List(_) => panic!("uniform breaks expected"),
            };
            block.x = refine(&block.x);
            block.y = refine(&block.y);
            let model = Model::build(&case, &path).unwrap();
            let solution = solve_static(&model, &mut |_| {}).unwrap();
            let h = 10.0 / (8 * k) as f64;
            (
                h,
                relative_l2_displacement_error(&model, &solution.u, model.exact.as_ref().unwrap()),
            )
        })
        .collect()
}

fn assert_rate(element: &str, order: f64) {
    let e = errors(element, &[1, 2, 4, 8]);
    for w in e.windows(2) {
        assert!(w[1].1 < w[0].1, "{element}: error did not fall: {e:?}");
    }
    let n = e.len();
    let rate = (e[n - 2].1 / e[n - 1].1).ln() / (e[n - 2].0 / e[n - 1].0).ln();
    eprintln!("{element}: errors {e:?}, finest rate {rate:.3}");
    assert!(
        rate >= order - 0.15 && rate < order + 0.7,
        "{element}: observed L2 rate {rate:.3}, expected {order}"
    );
}

#[test]
fn q4_converges_at_second_order() {
    assert_rate("q4", 2.0);
}

#[test]
fn t3_converges_at_second_order() {
    assert_rate("t3", 2.0);
}

#[test]
fn q9_converges_at_third_order() {
    assert_rate("q9", 3.0);
}

#[test]
fn t6_converges_at_third_order() {
    assert_rate("t6", 3.0);
}
