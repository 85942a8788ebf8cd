//! The panel's cleansing checkbox ([`CleanseSwitch`]): "Cleanse tagged fluid", greyed out with
//! the reason for a scan that is not a CT in Hounsfield units, a spinner while the scan is
//! cleansed or put back.

use crate::cleansing::CleanseSwitch;
use crate::session::Session;
use std::sync::Arc;

/// The checkbox's label.
const LABEL: &str = "Cleanse tagged fluid";

/// Draws the checkbox and starts a switch when it is clicked.
pub(crate) fn cleanse_ui(ui: &mut egui::Ui, switch: &mut CleanseSwitch, session: &Session) {
    let unavailable = CleanseSwitch::unavailable(session);
    let mut on = switch.is_on();
    ui.horizontal(|ui| {
        let enabled = unavailable.is_none() && !switch.running();
        let checkbox = ui.add_enabled(enabled, egui::Checkbox::new(&mut on, LABEL));
        let hint = "remove the oral-contrast-tagged fluid pooled under air (and its rims), so \
                    the wall under it shows; as --cleanse on";
        let checkbox = checkbox.on_hover_text(hint);
        if let Some(why) = &unavailable {
            checkbox.on_disabled_hover_text(why);
        }
        if switch.running() {
            ui.spinner();
        }
    });
    if on != switch.is_on() {
        let ctx = ui.ctx().clone();
        switch.set(on, session, Arc::new(move || ctx.request_repaint()));
    }
}
