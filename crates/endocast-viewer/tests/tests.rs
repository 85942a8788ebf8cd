//! The viewer's tests, in one binary (one link step): the session driven as the window drives
//! it, the case files, and the window itself on a headless egui context.

#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

mod case;
mod common;
mod compare;
mod flight;
mod harness;
mod plan_export;
mod review;
mod series;
mod ui;
mod ui_case;
mod ui_cleansing;
mod ui_dissection;
mod ui_tools;
