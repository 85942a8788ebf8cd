//! The panel's section of the review of what a flight missed ([`ReviewTools`]): start it,
//! follow its progress, the coverage with the patches visited, the next patch and the list.

use crate::review::ReviewTools;
use crate::session::Session;
use std::sync::Arc;

/// Draws the section; returns a line for the status bar when something was done.
pub(crate) fn review_ui(
    tools: &mut ReviewTools,
    ui: &mut egui::Ui,
    session: &mut Session,
) -> Option<String> {
    let mut said = None;
    let running = tools.frames_flown().is_some();
    ui.horizontal(|ui| {
        let hint = "fly the key frames (or the automatic path) and list the wall never seen";
        let start = ui.add_enabled(!running, egui::Button::new("Review unseen"));
        if start.on_hover_text(hint).clicked() {
            let ctx = ui.ctx().clone();
            tools.start(session, Arc::new(move || ctx.request_repaint()));
        }
        ui.checkbox(&mut tools.both_ways, "both ways");
        if ui.button("Next unseen (N)").clicked() {
            said = Some(tools.next(session));
        }
    });
    if let Some(frames) = tools.frames_flown() {
        ui.label(format!("flying: {frames} frames"));
    }
    if let Some((before, now)) = tools.coverage() {
        let left = tools.visited().iter().filter(|v| !**v).count();
        ui.label(format!(
            "coverage {:.1} % → {:.1} % with the patches visited; {left} of {} left ({} unseen in all)",
            100.0 * before,
            100.0 * now,
            tools.views().len(),
            tools.patches_total()
        ));
    }
    if let Some(n) = list_ui(tools, ui) {
        said = Some(tools.visit(session, n));
    }
    said
}

/// The listed patches with their area, visited ones ticked; returns the one clicked.
fn list_ui(tools: &ReviewTools, ui: &mut egui::Ui) -> Option<usize> {
    let mut clicked = None;
    egui::ScrollArea::vertical()
        .id_salt("unseen patches")
        .max_height(140.0)
        .show(ui, |ui| {
            for (n, (view, visited)) in tools.views().iter().zip(tools.visited()).enumerate() {
                let tick = if *visited { "✔" } else { "·" };
                let text = format!("{tick} {:3}: {:8.0} mm²", n + 1, view.patch.area_mm2);
                if ui.selectable_label(false, text).clicked() {
                    clicked = Some(n);
                }
            }
        });
    clicked
}
