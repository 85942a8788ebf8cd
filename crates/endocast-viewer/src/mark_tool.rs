//! The marking tool of the view: what clicks and drags do, and what it keeps between them.

/// What a click or a drag in the view does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) enum Tool {
    /// Turn toward the clicked point; drag to look around.
    #[default]
    Look,
    /// A click labels the surface point.
    Label,
    /// Dragging draws on the tissue.
    Draw,
    /// Two clicks measure the distance between two surface points.
    Measure,
}

/// The tool and what it keeps between inputs.
#[derive(Debug, Clone)]
pub(crate) struct MarkTool {
    /// The active tool.
    pub tool: Tool,
    /// The label of the next point or stroke.
    pub label: String,
    /// A measurement's first pixel, once clicked.
    pub measure_from: Option<[usize; 2]>,
}

impl Default for MarkTool {
    fn default() -> Self {
        Self {
            tool: Tool::Look,
            label: "mark".into(),
            measure_from: None,
        }
    }
}
