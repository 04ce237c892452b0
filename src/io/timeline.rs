//! The output of a time integration, beside `summary.json`: the per-step history
//! ([`crate::solver::history`]) as `history.json` and `history.csv`, SVG plots of the contact
//! force, the energies and the momentum against time (`contact-force.svg`, `energy.svg`,
//! `momentum.svg`), and for each body a ParaView collection `<body>.pvd` (VTK XML
//! `Collection`, one `DataSet` per frame with its `timestep`) of the frames
//! `<body>.frame-NNNN.vtu`, written like the run's `.vtu` files.

use crate::error::Result;
use crate::io::paths::file_name;
use crate::io::svg::{line_plot, Series};
use crate::model::{Body, Model};
use crate::solver::history::DynamicHistory;
use std::path::Path;

/// Writes one `.vtu` frame: `(path, body, global displacement)`.
pub type FrameWriter<'a> = &'a dyn Fn(&Path, &Body, &[f64]) -> Result<()>;

/// The files of a time integration, written into the (temporary) run folder `dir`;
/// `write_frame(path, body, u)` writes one `.vtu` frame (the run's own `.vtu` writer).
pub fn write_history(
    dir: &Path,
    model: &Model,
    history: &DynamicHistory,
    write_frame: FrameWriter<'_>,
) -> Result<()> {
    // every file is created new: a name taken by another output is refused there
    let write = |name: &str, text: &str| crate::io::paths::write_new_file(&dir.join(name), text);
    let json = serde_json::to_string_pretty(history).expect("the history serializes") + "\n";
    write("history.json", &json)?;
    write("history.csv", &history.csv())?;
    for (name, svg) in plots(history) {
        write(&name, &svg)?;
    }
    for body in &model.bodies {
        let mut collection = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n",
        );
        for (k, (time, u)) in history.frames.iter().enumerate() {
            let name = file_name("body name", &body.name, &format!(".frame-{k:04}.vtu"))?;
            write_frame(&dir.join(&name), body, u)?;
            collection.push_str(&format!(
                "<DataSet timestep=\"{time:e}\" group=\"\" part=\"0\" file=\"{name}\"/>\n"
            ));
        }
        collection.push_str("</Collection>\n</VTKFile>\n");
        let pvd = file_name("body name", &body.name, ".pvd")?;
        write(&pvd, &collection)?;
    }
    Ok(())
}

/// `(file name, SVG)` of the contact force, energy and momentum histories.
pub fn plots(history: &DynamicHistory) -> Vec<(String, String)> {
    let series = |name: &str, f: &dyn Fn(&crate::solver::history::StepRecord) -> f64| Series {
        name: name.to_string(),
        points: history.steps.iter().map(|s| (s.time, f(s))).collect(),
    };
    let title = format!(
        "{}, {} mass, {} (dt {:e})",
        history.integrator, history.mass, history.impact, history.dt
    );
    let mut momentum = vec![series("total p_x", &|s| s.momentum[0])];
    for (b, name) in history.body_names.iter().enumerate() {
        momentum.push(series(&format!("{name} p_x"), &move |s| {
            s.body_momentum[b][0]
        }));
    }
    vec![
        (
            "contact-force.svg".into(),
            line_plot(
                &format!("contact force: {title}"),
                "time",
                "contact force",
                &[series("contact force", &|s| s.contact_force)],
            ),
        ),
        (
            "energy.svg".into(),
            line_plot(
                &format!("energy: {title}"),
                "time",
                "energy",
                &[
                    series("total", &|s| s.total),
                    series("kinetic", &|s| s.kinetic),
                    series("strain", &|s| s.strain),
                    series("contact", &|s| s.contact_energy),
                ],
            ),
        ),
        (
            "momentum.svg".into(),
            line_plot(&format!("momentum: {title}"), "time", "momentum", &momentum),
        ),
    ]
}
