//! Driving the window headlessly: the application on an `egui::Context` fed synthetic input
//! (keys, pointer presses, drags, the wheel), finding widgets by the text they paint, and
//! keeping the picture last uploaded for the endoscopic view.

use egui::epaint::{ClippedShape, ImageData, Shape};
use egui::{Event, FullOutput, Key, Modifiers, PointerButton, Pos2, RawInput, Rect, Vec2};
use endocast_core::presets::Preset;
use endocast_viewer::app::{ViewerApp, ViewerOptions};
use endocast_viewer::scene::ScanSource;
use std::time::{Duration, Instant};

/// UI frames that outlast egui's animations (a frame without a clock advances it 1/60 s).
const ANIMATION_FRAMES: usize = 12;

/// The window's size, points.
pub const SCREEN: Vec2 = Vec2::new(1100.0, 700.0);

/// Opening `source` with the colonoscopy preset, nothing else.
pub fn options(source: ScanSource) -> ViewerOptions {
    ViewerOptions {
        source,
        preset: Preset::find("colonoscopy"),
        pose: None,
        case: None,
        screenshot: None,
        on_screenshot: None,
        look: None,
        layout: None,
        compare: None,
    }
}

/// One frame's input: `events` on the whole window.
pub fn input(events: Vec<Event>) -> RawInput {
    RawInput {
        screen_rect: Some(Rect::from_min_size(Pos2::ZERO, SCREEN)),
        events,
        ..RawInput::default()
    }
}

/// A key going down or up.
pub fn key(key: Key, pressed: bool) -> Event {
    Event::Key {
        key,
        physical_key: None,
        pressed,
        repeat: false,
        modifiers: Modifiers::NONE,
    }
}

/// Runs UI frames until `done` or the timeout.
pub fn run_until(ctx: &egui::Context, app: &mut ViewerApp, done: impl Fn(&ViewerApp) -> bool) {
    let start = Instant::now();
    while !done(app) {
        assert!(start.elapsed() < Duration::from_secs(120), "timed out");
        let _ = ctx.run(input(Vec::new()), |ctx| app.frame_ui(ctx));
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// The application in a headless window, with what its last frame painted.
pub struct Window {
    pub ctx: egui::Context,
    pub app: ViewerApp,
    shapes: Vec<ClippedShape>,
    /// The endoscopic view's picture as last uploaded (RGBA), and its size.
    pub view: Option<([usize; 2], Vec<u8>)>,
}

impl Window {
    /// The application opening `options`.
    pub fn open(options: ViewerOptions) -> Self {
        let ctx = egui::Context::default();
        let app = ViewerApp::new(ctx.clone(), options);
        Self {
            ctx,
            app,
            shapes: Vec::new(),
            view: None,
        }
    }

    /// One UI frame with `events`.
    pub fn frame(&mut self, events: Vec<Event>) {
        let app = &mut self.app;
        let output = self.ctx.run(input(events), |ctx| app.frame_ui(ctx));
        self.keep(output);
    }

    fn keep(&mut self, output: FullOutput) {
        let endoscope = self
            .ctx
            .tex_manager()
            .read()
            .allocated()
            .find(|(_, meta)| meta.name == "endoscope")
            .map(|(id, _)| *id);
        for (id, delta) in &output.textures_delta.set {
            if Some(*id) == endoscope && delta.pos.is_none() {
                let ImageData::Color(image) = &delta.image;
                let rgba = image.pixels.iter().flat_map(|c| c.to_array()).collect();
                self.view = Some((image.size, rgba));
            }
        }
        self.shapes = output.shapes;
    }

    /// Runs UI frames until `done` or two minutes.
    pub fn run_until(&mut self, done: impl Fn(&ViewerApp) -> bool) {
        let start = Instant::now();
        while !done(&self.app) {
            assert!(start.elapsed() < Duration::from_secs(120), "timed out");
            self.frame(Vec::new());
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// Runs UI frames until the view has refined to its last still and that picture is
    /// uploaded.
    pub fn settle(&mut self) {
        self.run_until(|app| {
            app.session().is_some_and(|s| {
                let worker = s.worker();
                worker.latest().is_some_and(|f| {
                    f.generation == worker.generation()
                        && f.stage
                            == endocast_core::render::progressive::Stage::Still(
                                endocast_viewer::worker::STILL_FRAMES,
                            )
                })
            })
        });
        // The frame that uploads it.
        self.frame(Vec::new());
    }

    /// Where the last frame painted `text` (the topmost of several) where it can be clicked.
    pub fn text_rect(&self, text: &str) -> Option<Rect> {
        let mut found: Vec<Rect> = Vec::new();
        for clipped in &self.shapes {
            texts(&clipped.shape, &mut |pos, shown, rect| {
                let rect = rect.translate(pos.to_vec2());
                if shown == text && clipped.clip_rect.contains_rect(rect) {
                    found.push(rect);
                }
            });
        }
        found.into_iter().min_by(|a, b| a.min.y.total_cmp(&b.min.y))
    }

    /// Where the last frame painted the texture named `name` (its whole picture, clipped or
    /// not), and the part of it left visible by its clip.
    pub fn image_rect(&self, name: &str) -> Option<(Rect, Rect)> {
        let id = self
            .ctx
            .tex_manager()
            .read()
            .allocated()
            .find(|(_, meta)| meta.name == name)
            .map(|(id, _)| *id)?;
        self.shapes.iter().find_map(|clipped| match &clipped.shape {
            Shape::Mesh(mesh) if mesh.texture_id == id => {
                let rect = mesh.calc_bounds();
                Some((rect, rect.intersect(clipped.clip_rect)))
            }
            _ => None,
        })
    }

    /// Every text the last frame painted and where, clipped or not.
    pub fn painted_text_rects(&self) -> Vec<(String, Rect)> {
        let mut all = Vec::new();
        for clipped in &self.shapes {
            texts(&clipped.shape, &mut |pos, shown, rect| {
                all.push((shown.to_owned(), rect.translate(pos.to_vec2())))
            });
        }
        all
    }

    /// Every text the last frame painted.
    pub fn painted_texts(&self) -> Vec<String> {
        let mut all = Vec::new();
        for clipped in &self.shapes {
            texts(&clipped.shape, &mut |_, shown, _| {
                all.push(shown.to_owned())
            });
        }
        all
    }

    /// Fails naming the texts of the last frame that the font cannot draw.
    pub fn assert_glyphs(&self) {
        let font = egui::FontId::proportional(14.0);
        let missing: Vec<_> = self
            .painted_texts()
            .into_iter()
            .filter(|t| !self.ctx.fonts_mut(|f| f.has_glyphs(&font, t)))
            .collect();
        assert!(missing.is_empty(), "drawn without glyphs: {missing:?}");
    }

    /// Where `text` is once the panel has stopped moving (a wheel's scroll is animated over
    /// several frames: a click aimed at the first frame's place would land beside it).
    fn settled_text_rect(&mut self, text: &str) -> Option<Rect> {
        let mut rect = self.text_rect(text)?;
        for _ in 0..60 {
            self.frame(Vec::new());
            let now = self.text_rect(text)?;
            if now == rect {
                return Some(now);
            }
            rect = now;
        }
        Some(rect)
    }

    /// Clicks the widget that shows `text`, scrolling the control panel down to it.
    pub fn click_text(&mut self, text: &str) {
        for _ in 0..40 {
            if let Some(rect) = self.settled_text_rect(text) {
                self.click(rect.center());
                return;
            }
            // Scroll the control panel (the pointer over it) one step down.
            self.frame(vec![
                Event::PointerMoved(Pos2::new(100.0, 300.0)),
                Event::MouseWheel {
                    unit: egui::MouseWheelUnit::Point,
                    delta: Vec2::new(0.0, -150.0),
                    modifiers: Modifiers::NONE,
                },
            ]);
            self.frame(Vec::new());
        }
        panic!("no {text:?} to click in the window");
    }

    /// A press and release of the primary button at `pos`, and the frames that finish what it
    /// animates (a header unfolding).
    pub fn click(&mut self, pos: Pos2) {
        self.frame(vec![Event::PointerMoved(pos)]);
        self.frame(vec![button(pos, true)]);
        self.frame(vec![button(pos, false)]);
        for _ in 0..ANIMATION_FRAMES {
            self.frame(Vec::new());
        }
    }

    /// Two presses and releases of the primary button at `pos`, quickly.
    pub fn double_click(&mut self, pos: Pos2) {
        self.frame(vec![Event::PointerMoved(pos)]);
        for _ in 0..2 {
            self.frame(vec![button(pos, true)]);
            self.frame(vec![button(pos, false)]);
        }
        for _ in 0..ANIMATION_FRAMES {
            self.frame(Vec::new());
        }
    }

    /// How many line segments of colour `rgb` (within 3 levels, at any opacity) the last frame
    /// painted.
    pub fn segments_coloured(&self, rgb: [u8; 3]) -> usize {
        let mut count = 0;
        for clipped in &self.shapes {
            segments(&clipped.shape, &mut |colour| {
                let drawn = colour.to_srgba_unmultiplied();
                count += usize::from(rgb.iter().zip(drawn).all(|(a, b)| a.abs_diff(b) <= 3));
            });
        }
        count
    }

    /// The wheel turned by `delta` points (up: positive) over `pos` with `modifiers` held, and
    /// the frames that finish what it animates.
    pub fn wheel(&mut self, pos: Pos2, delta: f32, modifiers: Modifiers) {
        self.frame(vec![Event::PointerMoved(pos)]);
        self.frame(vec![Event::MouseWheel {
            unit: egui::MouseWheelUnit::Point,
            delta: Vec2::new(0.0, delta),
            modifiers,
        }]);
        for _ in 0..ANIMATION_FRAMES {
            self.frame(Vec::new());
        }
    }

    /// A drag with the primary button from `from` to `to` in `steps` moves.
    pub fn drag(&mut self, from: Pos2, to: Pos2, steps: usize) {
        self.frame(vec![Event::PointerMoved(from)]);
        self.frame(vec![button(from, true)]);
        for k in 1..=steps {
            let pos = from.lerp(to, k as f32 / steps as f32);
            self.frame(vec![Event::PointerMoved(pos)]);
        }
        self.frame(vec![button(to, false)]);
    }
}

fn button(pos: Pos2, pressed: bool) -> Event {
    Event::PointerButton {
        pos,
        button: PointerButton::Primary,
        pressed,
        modifiers: Modifiers::NONE,
    }
}

/// Calls `f` with the colour of each line segment in `shape`.
fn segments(shape: &Shape, f: &mut impl FnMut(egui::Color32)) {
    match shape {
        Shape::LineSegment { stroke, .. } => f(stroke.color),
        Shape::Vec(shapes) => shapes.iter().for_each(|s| segments(s, f)),
        _ => {}
    }
}

/// Calls `f` with each text shape's position, text and galley rectangle in `shape`.
fn texts(shape: &Shape, f: &mut impl FnMut(Pos2, &str, Rect)) {
    match shape {
        Shape::Text(t) => f(t.pos, t.galley.text(), t.galley.rect),
        Shape::Vec(shapes) => shapes.iter().for_each(|s| texts(s, f)),
        _ => {}
    }
}
