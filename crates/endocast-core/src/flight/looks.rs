//! The render settings of each shot: the flight's own, or, for a key frame, the flight's with
//! the key frame's isovalue, isosurface opacity and transfer function ([`ShotLook`]). A key
//! frame names its transfer function (a preset or a file); the caller says how a name becomes
//! a [`TransferFunction`] (the io crate reads files) and each name is loaded once.

use super::{Shot, ShotLook};
use crate::render::{RenderSettings, TransferFunction};

/// Render settings per shot, with each named transfer function loaded once.
#[derive(Debug)]
pub struct ShotSettings<F> {
    base: RenderSettings,
    load: F,
    loaded: Vec<(String, TransferFunction)>,
}

impl<F, E> ShotSettings<F>
where
    F: FnMut(&str) -> Result<TransferFunction, E>,
{
    /// Settings based on the flight's `base`, loading a key frame's transfer function by name
    /// with `load` the first time a shot names it.
    pub fn new(base: RenderSettings, load: F) -> Self {
        Self {
            base,
            load,
            loaded: Vec::new(),
        }
    }

    /// The settings of `shot`: the base settings, with its key frame's look when it has one.
    /// Fails only when the look names a transfer function `load` cannot give.
    pub fn for_shot(&mut self, shot: &Shot) -> Result<RenderSettings, E> {
        let mut settings = self.base.clone();
        let Some(look) = &shot.look else {
            return Ok(settings);
        };
        self.apply(look, &mut settings)?;
        Ok(settings)
    }

    /// Sets the isovalue, opacity and (when named) transfer function of `look` in `settings`.
    fn apply(&mut self, look: &ShotLook, settings: &mut RenderSettings) -> Result<(), E> {
        settings.iso_hu = look.iso_hu;
        settings.iso_opacity = look.iso_opacity;
        if let Some(name) = &look.tf {
            if let Some((_, tf)) = self.loaded.iter().find(|(n, _)| n == name) {
                settings.tf = tf.clone();
            } else {
                let tf = (self.load)(name)?;
                settings.tf = tf.clone();
                self.loaded.push((name.clone(), tf));
            }
        }
        Ok(())
    }
}
