//! The `endocast` command-line tool.

fn main() {}
