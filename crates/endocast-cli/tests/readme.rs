//! README.md as a contract (issue 31): every command of its `sh` blocks runs as written, and
//! every picture a command writes to `docs/examples/` is the one committed there.
//!
//! The blocks run one after another in one scratch folder, each command by `bash` with the
//! variables assigned so far (`S=...`), as one shell would run them; `endocast` and
//! `cargo run --release -p endocast-cli --` are the binary cargo built for this test (or
//! `$ENDOCAST`). `../shared/data` resolves from the scratch folder to the shared scans; a block
//! that reads them is skipped with a visible line when they are absent, and fails under CI. A
//! command that cannot run here says why. `text` blocks are usage lists, not commands; the
//! `python` block is run by the Python package's tests.
//!
//! Pictures: a command whose output is `docs/examples/NAME.png` writes it in the scratch folder,
//! and the test compares it with the committed one within [`Tolerance`].
//! `ENDOCAST_README_PICTURES=write` copies them over the committed ones instead
//! (`bench/readme_pictures.sh`).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The repository's root.
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// One command of a fenced `sh` block, its `\`-continued lines joined.
#[derive(Debug)]
struct Command {
    /// The README line it starts on.
    line: usize,
    /// The command as written.
    text: String,
}

/// The `sh` blocks of `readme`, each a list of commands (comments and blank lines left out).
/// Every fenced block must say its kind: `sh`, `text` or `python`.
fn sh_blocks(readme: &str) -> Vec<Vec<Command>> {
    let mut blocks = Vec::new();
    let mut fence: Option<(String, Vec<Command>)> = None;
    let mut text = String::new();
    let mut start = 0;
    for (index, line) in readme.lines().enumerate() {
        if let Some(kind) = line.strip_prefix("```") {
            match fence.take() {
                Some((kind, block)) if kind == "sh" => blocks.push(block),
                Some(_) => {}
                None => {
                    assert!(
                        ["sh", "text", "python"].contains(&kind),
                        "README.md:{}: a fenced block must say sh, text or python, not {kind:?}",
                        index + 1
                    );
                    fence = Some((kind.to_string(), Vec::new()));
                }
            }
            continue;
        }
        let Some((_, block)) = fence.as_mut() else {
            continue;
        };
        if text.is_empty() {
            start = index + 1;
        }
        let line = line.trim();
        if let Some(head) = line.strip_suffix('\\') {
            text.push_str(head.trim_end());
            text.push(' ');
            continue;
        }
        text.push_str(line);
        if !text.is_empty() && !text.starts_with('#') {
            block.push(Command {
                line: start,
                text: std::mem::take(&mut text),
            });
        }
        text.clear();
    }
    blocks
}

/// The command as `bash` runs it here: `cargo run --release -p endocast-cli --` is `endocast`.
fn as_run(text: &str) -> String {
    text.replace("cargo run --release -p endocast-cli --", "endocast")
}

/// Why a command cannot run in this test, or `None` when it can. A viewer's screenshot runs
/// under `xvfb-run` when `xvfb` is set (`ENDOCAST_README_XVFB=1`, as `bench/readme_pictures.sh`
/// sets it); its status line shows the still count and times, which vary from run to run.
fn cannot_run(text: &str, xvfb: bool) -> Option<&'static str> {
    let words: Vec<&str> = text.split_whitespace().collect();
    match words.as_slice() {
        ["cargo", "install", ..] => {
            Some("installs into ~/.cargo/bin; the test runs the binary cargo built for it")
        }
        ["cargo", "test", ..] => Some("the test command itself (this test is one of its tests)"),
        ["endocast", "view", ..] if words.contains(&"--screenshot") && !xvfb => Some(
            "a window under Xvfb (45 s in the debug build) whose still count and timings vary: \
             bench/readme_pictures.sh runs it (ENDOCAST_README_XVFB=1)",
        ),
        ["endocast", "view", ..] if !words.contains(&"--screenshot") => {
            Some("opens a window until it is closed")
        }
        _ => None,
    }
}

/// What `bash` runs for `text`: a viewer's screenshot under `xvfb-run`.
fn with_display(text: &str) -> String {
    if text.starts_with("endocast view ") {
        format!("xvfb-run -a -s '-screen 0 1280x1024x24' {text}")
    } else {
        text.to_string()
    }
}

/// A variable assignment `NAME=VALUE`: its name.
fn assigned(text: &str) -> Option<&str> {
    let (name, _) = text.split_once('=')?;
    let valid = !name.is_empty()
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !name.starts_with(|c: char| c.is_ascii_digit());
    valid.then_some(name)
}

/// What a command writes: the word after `-o`, `--output` or `--screenshot`, `cp`'s last word,
/// `annotate`'s case.
fn outputs(text: &str) -> Vec<String> {
    let words: Vec<&str> = text.split_whitespace().collect();
    let mut found: Vec<String> = words
        .windows(2)
        .filter(|w| ["-o", "--output", "--screenshot"].contains(&w[0]))
        .map(|w| w[1].to_string())
        .collect();
    match words.as_slice() {
        ["cp", .., last] => found.push(last.to_string()),
        ["endocast", "annotate", case, ..] => found.push(case.to_string()),
        _ => {}
    }
    found.retain(|o| !o.contains('$'));
    found
}

/// The limits within which a picture made now matches the committed one: rendering is
/// deterministic and independent of the thread count and of the CPU's vector instructions
/// (the AVX2 paths are bit-identical to the scalar ones), so these only absorb what a
/// different floating-point library (`exp`, `pow`, `sin`) could move by a unit here and there.
struct Tolerance;

impl Tolerance {
    /// A pixel differs when one of its channels differs by more than this (of 255).
    const CHANNEL: u8 = 24;
    /// At most this share of the pixels may differ.
    const SHARE_DIFFERING: f64 = 0.01;
    /// The mean absolute difference over every channel of every pixel, at most (of 255).
    const MEAN: f64 = 2.0;
}

/// A PNG's width, height and pixels as RGB.
fn read_rgb(path: &Path) -> Result<(u32, u32, Vec<u8>), String> {
    let file = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let decoder = png::Decoder::new(std::io::BufReader::new(file));
    let mut reader = decoder
        .read_info()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader
        .next_frame(&mut pixels)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let channels = info.line_size / info.width as usize;
    assert!(
        channels >= 3 && info.bit_depth == png::BitDepth::Eight,
        "{}: not 8-bit RGB(A)",
        path.display()
    );
    let rgb = pixels[..info.buffer_size()]
        .chunks(channels)
        .flat_map(|p| p[..3].to_vec())
        .collect();
    Ok((info.width, info.height, rgb))
}

/// How `made` differs from `committed`: `Err` with the numbers when beyond [`Tolerance`].
fn compare(made: &Path, committed: &Path) -> Result<String, String> {
    let (w, h, a) = read_rgb(made)?;
    let (cw, ch, b) = read_rgb(committed)?;
    if (w, h) != (cw, ch) {
        return Err(format!("{w}×{h}, the committed picture is {cw}×{ch}"));
    }
    let differing = a
        .chunks(3)
        .zip(b.chunks(3))
        .filter(|(p, q)| {
            p.iter()
                .zip(*q)
                .any(|(x, y)| x.abs_diff(*y) > Tolerance::CHANNEL)
        })
        .count();
    let total: u64 = a
        .iter()
        .zip(&b)
        .map(|(x, y)| u64::from(x.abs_diff(*y)))
        .sum();
    let share = differing as f64 / f64::from(w * h);
    let mean = total as f64 / a.len() as f64;
    let numbers = format!(
        "{:.3} % of the pixels differ by more than {} (at most {} %), mean difference {mean:.3} \
         (at most {})",
        share * 100.0,
        Tolerance::CHANNEL,
        Tolerance::SHARE_DIFFERING * 100.0,
        Tolerance::MEAN
    );
    if share <= Tolerance::SHARE_DIFFERING && mean <= Tolerance::MEAN {
        Ok(numbers)
    } else {
        Err(numbers)
    }
}

/// Says `line` on the terminal, past the test harness's capture.
fn say(line: &str) {
    let _ = writeln!(std::io::stderr(), "{line}");
}

/// The scratch folder: `work/` to run in (with a link to the repository's `bench/`), `shared`
/// beside it (a link to the shared scans' folder when they are here), and `bin/endocast`.
struct Scratch {
    _dir: tempfile::TempDir,
    work: PathBuf,
    bin: PathBuf,
    has_shared: bool,
}

impl Scratch {
    /// Makes the folder; the binary is `$ENDOCAST` when set, else the one cargo built.
    fn new() -> Self {
        let dir = tempfile::tempdir().unwrap();
        let work = dir.path().join("work");
        let bin = dir.path().join("bin");
        std::fs::create_dir_all(work.join("docs/examples")).unwrap();
        std::fs::create_dir_all(&bin).unwrap();
        let binary = std::env::var_os("ENDOCAST").map_or_else(
            || PathBuf::from(env!("CARGO_BIN_EXE_endocast")),
            PathBuf::from,
        );
        std::os::unix::fs::symlink(&binary, bin.join("endocast")).unwrap();
        // README's helper scripts (e.g. bench/tube_obj.py) run as from the repository's root.
        std::os::unix::fs::symlink(root().join("bench"), work.join("bench")).unwrap();
        let shared = endocast_testdata::shared_data("");
        if let Some(data) = &shared {
            let folder = data.canonicalize().unwrap().parent().unwrap().to_path_buf();
            std::os::unix::fs::symlink(folder, dir.path().join("shared")).unwrap();
        }
        Scratch {
            _dir: dir,
            work,
            bin,
            has_shared: shared.is_some(),
        }
    }

    /// Runs `command` after `variables` by bash in `work/`; `Err` with its output on failure.
    fn run(&self, variables: &str, command: &str) -> Result<(), String> {
        let path = std::env::var_os("PATH").unwrap_or_default();
        let mut paths = vec![self.bin.clone()];
        paths.extend(std::env::split_paths(&path));
        let out = std::process::Command::new("bash")
            .arg("-c")
            .arg(format!("set -eu\n{variables}{command}"))
            .current_dir(&self.work)
            .env("PATH", std::env::join_paths(paths).unwrap())
            .output()
            .expect("bash runs");
        if out.status.success() {
            return Ok(());
        }
        Err(format!(
            "{}\n{}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        ))
    }
}

/// The shell's state between commands: the variables assigned so far, and which of them name
/// the shared scans.
#[derive(Default)]
struct Shell {
    /// The assignments, one a line, as written.
    variables: String,
    /// The variables whose value reads `../shared/data`.
    shared: Vec<String>,
}

impl Shell {
    /// Whether `text` reads the shared scans, directly or through a variable.
    fn reads_shared(&self, text: &str) -> bool {
        text.contains("../shared/data")
            || self.shared.iter().any(|v| text.contains(&format!("${v}")))
    }

    /// Takes in the assignments of `block`; whether any of its commands reads the shared scans.
    fn take_block(&mut self, block: &[Command]) -> bool {
        let mut reads = false;
        for command in block {
            let text = as_run(&command.text);
            let shared = self.reads_shared(&text);
            reads |= shared;
            if let Some(name) = assigned(&text) {
                self.variables.push_str(&text);
                self.variables.push('\n');
                if shared {
                    self.shared.push(name.to_string());
                }
            }
        }
        reads
    }
}

/// Checks what a command wrote; pictures against the committed ones (or written over them).
fn check_outputs(scratch: &Scratch, command: &Command, failures: &mut Vec<String>) {
    let write = std::env::var("ENDOCAST_README_PICTURES").is_ok_and(|v| v == "write");
    for output in outputs(&command.text) {
        let made = scratch.work.join(&output);
        let size = std::fs::metadata(&made).map(|m| m.len()).unwrap_or(0);
        let is_folder = made.is_dir();
        if size == 0 && !is_folder {
            failures.push(format!(
                "README.md:{}: `{}` did not write {output}",
                command.line, command.text
            ));
            continue;
        }
        if !(output.starts_with("docs/examples/") && output.ends_with(".png")) {
            continue;
        }
        let committed = root().join(&output);
        match compare(&made, &committed) {
            Ok(numbers) => say(&format!("picture {output} matches: {numbers}")),
            // Writing: a picture within the tolerance keeps its committed bytes.
            Err(numbers) if write => {
                std::fs::copy(&made, &committed).unwrap();
                say(&format!("wrote {output}: {numbers}"));
            }
            Err(numbers) => failures.push(format!(
                "README.md:{}: the picture {output} no longer matches its command `{}`: \
                 {numbers} (bench/readme_pictures.sh makes it again)",
                command.line, command.text
            )),
        }
    }
}

#[test]
fn every_readme_command_runs_as_written_and_makes_its_picture() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let scratch = Scratch::new();
    let mut shell = Shell::default();
    let mut failures = Vec::new();
    for block in sh_blocks(&readme) {
        if shell.take_block(&block) && !scratch.has_shared {
            say(&format!(
                "SKIPPED (checked nothing): the block at README.md:{} reads ../shared/data",
                block[0].line
            ));
            continue;
        }
        for command in &block {
            run_command(&scratch, &shell, command, &mut failures);
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// Runs one command (unless it is an assignment, or cannot run here, saying why) and checks
/// what it wrote.
fn run_command(scratch: &Scratch, shell: &Shell, command: &Command, failures: &mut Vec<String>) {
    let text = as_run(&command.text);
    if assigned(&text).is_some() {
        return;
    }
    let xvfb = std::env::var("ENDOCAST_README_XVFB").is_ok_and(|v| v == "1");
    if let Some(why) = cannot_run(&text, xvfb) {
        say(&format!(
            "SKIPPED README.md:{} `{}`: {why}",
            command.line, command.text
        ));
        return;
    }
    let start = Instant::now();
    match scratch.run(&shell.variables, &with_display(&text)) {
        Ok(()) => check_outputs(scratch, command, failures),
        Err(why) => failures.push(format!(
            "README.md:{}: `{}` failed: {why}",
            command.line, command.text
        )),
    }
    say(&format!(
        "ran README.md:{} in {:.1} s",
        command.line,
        start.elapsed().as_secs_f64()
    ));
}

#[test]
fn blocks_are_read_as_a_shell_reads_them() {
    let readme = "```sh\nS=a\n# a comment\nendocast render $S \\\n    -o x.png\n\n```\n\
                  ```text\nendocast info PATH\n```\n";
    let blocks = sh_blocks(readme);
    assert_eq!(blocks.len(), 1);
    let texts: Vec<&str> = blocks[0].iter().map(|c| c.text.as_str()).collect();
    assert_eq!(texts, ["S=a", "endocast render $S -o x.png"]);
    assert_eq!(blocks[0][1].line, 4);
    assert_eq!(outputs(texts[1]), ["x.png"]);
    assert_eq!(assigned(texts[0]), Some("S"));
    assert_eq!(assigned(texts[1]), None);
    assert_eq!(
        outputs("cp a/b.png docs/examples/c.png"),
        ["docs/examples/c.png"]
    );
    assert!(cannot_run("endocast view --phantom colon", true).is_some());
    assert!(cannot_run("endocast view x --screenshot y.png", false).is_some());
    assert!(cannot_run("endocast view x --screenshot y.png", true).is_none());
    assert!(cannot_run("endocast render x -o y.png", false).is_none());
}
