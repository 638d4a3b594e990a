//! The README and the manual stay true: every relative link in README.md and docs/*.md reaches
//! a file (and, with an anchor, a heading of it), every `docs/<page>.md#<anchor>` the sources
//! name resolves the same way, and the README's commands run as written.
//!
//! Anchors are GitHub's: a heading's text (markdown removed), lower-cased, with every character
//! but letters, digits, `_`, `-` and spaces dropped and spaces turned into hyphens; a repeated
//! heading gets `-1`, `-2`, ….

mod common;

use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use common::cli::assert_success;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// README.md and every page of docs/, as paths relative to the repository.
fn markdown_files() -> Vec<PathBuf> {
    let mut pages: Vec<PathBuf> = std::fs::read_dir(repo().join("docs"))
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "md"))
        .map(|path| path.strip_prefix(repo()).unwrap().to_path_buf())
        .collect();
    pages.sort();
    pages.insert(0, PathBuf::from("README.md"));
    pages
}

// ---------------------------------------------------------------------------------------------
// Markdown: code, links and headings
// ---------------------------------------------------------------------------------------------

/// A fenced code block: its info string, its lines and the line number of its first line.
struct CodeBlock {
    info: String,
    first_line: usize,
    lines: Vec<String>,
}

/// The opening fence of a code block (three or more backticks or tildes), if the line is one.
fn fence(line: &str) -> Option<(char, usize, &str)> {
    let trimmed = line.trim_start();
    if line.len() - trimmed.len() > 3 {
        return None;
    }
    let c = trimmed.chars().next()?;
    if c != '`' && c != '~' {
        return None;
    }
    let n = trimmed.chars().take_while(|&x| x == c).count();
    (n >= 3).then(|| (c, n, trimmed[n..].trim()))
}

/// Splits a markdown file into its prose (code blocks blanked, line numbers kept) and its code
/// blocks.
fn split_code(text: &str) -> (String, Vec<CodeBlock>) {
    let mut prose = String::new();
    let mut blocks = Vec::new();
    let mut open: Option<(char, usize, CodeBlock)> = None;
    for (i, line) in text.lines().enumerate() {
        match &mut open {
            None => match fence(line) {
                Some((c, n, info)) => {
                    open = Some((c, n, CodeBlock { info: info.to_string(), first_line: i + 2, lines: vec![] }))
                }
                None => prose.push_str(line),
            },
            Some((c, n, block)) => {
                let trimmed = line.trim();
                let closes = trimmed.chars().all(|x| x == *c) && trimmed.len() >= *n;
                if closes {
                    blocks.push(open.take().unwrap().2);
                } else {
                    block.lines.push(line.to_string());
                }
            }
        }
        prose.push('\n');
    }
    assert!(open.is_none(), "a code block is never closed");
    (prose, blocks)
}

/// Blanks inline code spans (a run of n backticks up to the next run of exactly n), keeping
/// their contents' length so that positions and line numbers stay.
fn blank_inline_code(text: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    let mut out: Vec<char> = chars.clone();
    let run = |at: usize| chars[at..].iter().take_while(|&&c| c == '`').count();
    let mut i = 0;
    while i < chars.len() {
        if chars[i] != '`' {
            i += 1;
            continue;
        }
        let n = run(i);
        let mut j = i + n;
        let mut close = None;
        while j < chars.len() {
            if chars[j] == '`' {
                let m = run(j);
                if m == n {
                    close = Some(j);
                    break;
                }
                j += m;
            } else {
                j += 1;
            }
        }
        match close {
            Some(j) => {
                for c in &mut out[i + n..j] {
                    if *c != '\n' {
                        *c = ' ';
                    }
                }
                i = j + n;
            }
            None => i += n,
        }
    }
    out.into_iter().collect()
}

/// Every link target in markdown prose (code already blanked), with its line number:
/// `[text](target)`, `![alt](target)`, reference definitions `[label]: target`, and HTML
/// `src="…"` and `href="…"`.
fn link_targets(prose: &str) -> Vec<(usize, String)> {
    let line_of = |at: usize| prose[..at].matches('\n').count() + 1;
    let mut targets = Vec::new();
    for (at, _) in prose.match_indices("](") {
        let rest = &prose[at + 2..];
        let mut depth = 0;
        let end = rest
            .char_indices()
            .find(|&(_, c)| match c {
                '(' => {
                    depth += 1;
                    false
                }
                ')' if depth == 0 => true,
                ')' => {
                    depth -= 1;
                    false
                }
                _ => false,
            })
            .map(|(i, _)| i)
            .unwrap_or_else(|| panic!("line {}: a link's target is never closed", line_of(at)));
        let inside = rest[..end].trim();
        // An optional title follows the target after a space: [text](target "title").
        let target = inside.split_whitespace().next().unwrap_or("");
        let target = target.strip_prefix('<').and_then(|t| t.strip_suffix('>')).unwrap_or(target);
        targets.push((line_of(at), target.to_string()));
    }
    for (i, line) in prose.lines().enumerate() {
        let trimmed = line.trim_start();
        if let Some(rest) = trimmed.strip_prefix('[') {
            if let Some(close) = rest.find("]:") {
                if !rest[..close].contains('[') {
                    if let Some(target) = rest[close + 2..].split_whitespace().next() {
                        targets.push((i + 1, target.to_string()));
                    }
                }
            }
        }
        for attribute in ["src=\"", "href=\""] {
            for (at, _) in line.match_indices(attribute) {
                let rest = &line[at + attribute.len()..];
                let end = rest.find('"').unwrap_or_else(|| panic!("line {}: an unclosed {attribute}", i + 1));
                targets.push((i + 1, rest[..end].to_string()));
            }
        }
    }
    targets
}

/// A heading's anchor as GitHub makes it, before duplicates are numbered: the text lower-cased,
/// every character but letters, digits, `_`, `-` and spaces dropped, spaces turned into hyphens.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|&c| c.is_alphanumeric() || c == '_' || c == '-' || c == ' ')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// A heading's text as GitHub renders it: links replaced by their text, code spans by their
/// contents, and any closing run of `#` removed.
fn heading_text(raw: &str) -> String {
    let mut text = raw.trim();
    let without_closing = text.trim_end_matches('#');
    if without_closing.is_empty() || without_closing.ends_with(' ') {
        text = without_closing.trim_end();
    }
    let mut out = String::new();
    let mut rest = text;
    while let Some(open) = rest.find('[') {
        out.push_str(&rest[..open]);
        let after = &rest[open + 1..];
        match after.find("](").and_then(|mid| after[mid..].find(')').map(|close| (mid, mid + close))) {
            Some((mid, close)) => {
                out.push_str(&after[..mid]);
                rest = &after[close + 1..];
            }
            None => {
                out.push('[');
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out.replace('`', "")
}

/// The anchors of a markdown file's headings (ATX headings outside code blocks), numbered as
/// GitHub numbers repeated ones.
fn anchors(text: &str) -> HashSet<String> {
    let (prose, _) = split_code(text);
    let mut occurrences: HashMap<String, usize> = HashMap::new();
    let mut anchors = HashSet::new();
    for line in prose.lines() {
        let trimmed = line.trim_start();
        if line.len() - trimmed.len() > 3 {
            continue;
        }
        let level = trimmed.chars().take_while(|&c| c == '#').count();
        if !(1..=6).contains(&level) {
            continue;
        }
        let rest = &trimmed[level..];
        if !(rest.is_empty() || rest.starts_with(' ') || rest.starts_with('\t')) {
            continue;
        }
        let base = slug(&heading_text(rest));
        let mut anchor = base.clone();
        while occurrences.contains_key(&anchor) {
            let n = occurrences.get_mut(&base).unwrap();
            *n += 1;
            anchor = format!("{base}-{n}");
        }
        occurrences.insert(anchor.clone(), 0);
        anchors.insert(anchor);
    }
    anchors
}

/// Checks one relative link from the file `from` (relative to the repository): the file exists,
/// and an anchor is a heading of it. Returns the problem, if any.
fn check_link(from: &Path, target: &str, cache: &mut BTreeMap<PathBuf, HashSet<String>>) -> Option<String> {
    let (path, anchor) = match target.split_once('#') {
        Some((path, anchor)) => (path, Some(anchor)),
        None => (target, None),
    };
    let file = if path.is_empty() { from.to_path_buf() } else { from.parent().unwrap().join(path) };
    let on_disk = repo().join(&file);
    if !on_disk.exists() {
        return Some(format!("{target}: {} does not exist", file.display()));
    }
    let anchor = anchor?;
    if on_disk.extension().is_none_or(|e| e != "md") {
        return Some(format!("{target}: an anchor into a file that is not markdown"));
    }
    let known = cache.entry(on_disk.canonicalize().unwrap()).or_insert_with(|| anchors(&read(&on_disk)));
    if known.contains(anchor) {
        return None;
    }
    let mut close: Vec<&String> = known.iter().filter(|a| a.contains(anchor) || anchor.contains(a.as_str())).collect();
    close.sort();
    Some(format!("{target}: {} has no heading with the anchor #{anchor} (similar: {close:?})", file.display()))
}

fn is_external(target: &str) -> bool {
    ["http://", "https://", "mailto:"].iter().any(|scheme| target.starts_with(scheme))
}

#[test]
fn slugs_follow_github() {
    assert_eq!(slug(&heading_text("`lookdev render`")), "lookdev-render");
    assert_eq!(
        slug(&heading_text("`lookdev view [LOOK.toml] [--gbuffer FILE] [--env FILE] [--device NAME]`")),
        "lookdev-view-looktoml---gbuffer-file---env-file---device-name"
    );
    assert_eq!(
        slug(&heading_text("`lookdev bake MODEL.gltf|.glb --out GBUFFER.exr`")),
        "lookdev-bake-modelgltfglb---out-gbufferexr"
    );
    assert_eq!(slug(&heading_text("Shading, BRDF models and sampling")), "shading-brdf-models-and-sampling");
    assert_eq!(slug(&heading_text("It's (mostly) a/b: `x_y` & z")), "its-mostly-ab-x_y--z");
    assert_eq!(slug(&heading_text("Naïve café ×2")), "naïve-café-2");
    assert_eq!(slug(&heading_text("See [the formats](formats.md#looks) ##")), "see-the-formats");
    let repeated = anchors("# A\n\n## A\n\n```\n# A\n```\n\n### A\n\n# A-1\n");
    let expected: HashSet<String> = ["a", "a-1", "a-2", "a-1-1"].iter().map(|s| s.to_string()).collect();
    assert_eq!(repeated, expected);
}

#[test]
fn inline_code_and_code_blocks_hold_no_links() {
    let (prose, blocks) = split_code("a [x](one.md) `[y](two.md)`\n```sh\n[z](three.md)\n```\n``[w](`four.md`)``\n");
    let targets: Vec<String> = link_targets(&blank_inline_code(&prose)).into_iter().map(|(_, t)| t).collect();
    assert_eq!(targets, ["one.md"]);
    assert_eq!(blocks.len(), 1);
    assert_eq!(blocks[0].lines, ["[z](three.md)"]);
}

#[test]
fn broken_links_are_reported() {
    let mut cache = BTreeMap::new();
    let readme = Path::new("README.md");
    let commands = Path::new("docs/commands.md");
    assert_eq!(check_link(readme, "docs/formats.md#looks", &mut cache), None);
    assert_eq!(check_link(commands, "formats.md#aovs", &mut cache), None);
    assert_eq!(check_link(commands, "#lookdev-render", &mut cache), None);
    assert_eq!(check_link(readme, "docs/images/viewer.png", &mut cache), None);
    let problem = |target: &str, cache: &mut BTreeMap<PathBuf, HashSet<String>>| {
        check_link(readme, target, cache).unwrap_or_else(|| panic!("{target} was not reported"))
    };
    assert!(problem("docs/formats.md#look", &mut cache).contains("no heading with the anchor #look"));
    assert!(problem("docs/shading.md#brdf-model", &mut cache).contains("brdf-models"), "the near miss is suggested");
    assert!(problem("docs/no-such-page.md", &mut cache).contains("does not exist"));
    assert!(problem("docs/images/viewer.png#top", &mut cache).contains("not markdown"));
    assert!(check_link(commands, "docs/formats.md", &mut cache).is_some(), "resolved from the page's own folder");

    // A page as the test reads it: only the broken link is reported, with its line.
    let (prose, _) = split_code(
        "# Page\n\nSee [looks](docs/formats.md#looks),\n[AOVs](docs/formats.md#aov) and `[x](docs/x.md)`.\n",
    );
    let broken: Vec<(usize, String)> = link_targets(&blank_inline_code(&prose))
        .into_iter()
        .filter_map(|(line, target)| check_link(readme, &target, &mut cache).map(|p| (line, p)))
        .collect();
    assert_eq!(broken.len(), 1, "{broken:?}");
    assert_eq!(broken[0].0, 4);
    assert!(broken[0].1.starts_with("docs/formats.md#aov:"), "{broken:?}");
}

/// (a) Every relative link of README.md and docs/*.md reaches a file, and an anchor a heading
/// of its page; the README lists every page of docs/.
#[test]
fn links_in_readme_and_docs_resolve() {
    let mut cache = BTreeMap::new();
    let mut problems = Vec::new();
    let mut checked = 0;
    let mut readme_targets = HashSet::new();
    for file in markdown_files() {
        let (prose, _) = split_code(&read(&repo().join(&file)));
        for (line, target) in link_targets(&blank_inline_code(&prose)) {
            if is_external(&target) {
                continue;
            }
            checked += 1;
            if target.is_empty() {
                problems.push(format!("{}:{line}: an empty link", file.display()));
            } else if let Some(problem) = check_link(&file, &target, &mut cache) {
                problems.push(format!("{}:{line}: {problem}", file.display()));
            }
            if file == Path::new("README.md") {
                readme_targets.insert(target.split('#').next().unwrap().to_string());
            }
        }
    }
    for page in markdown_files().into_iter().skip(1) {
        if !readme_targets.contains(page.to_str().unwrap()) {
            problems.push(format!("README.md: the table of contents does not link {}", page.display()));
        }
    }
    assert!(problems.is_empty(), "{} of {checked} links are broken:\n{}", problems.len(), problems.join("\n"));
    assert!(checked > 40, "only {checked} links found: is the link parser broken?");
}

// ---------------------------------------------------------------------------------------------
// References to docs/ in the sources
// ---------------------------------------------------------------------------------------------

/// The files whose text may name a page of docs/: the Rust sources (src/, tests/ but this file,
/// fuzz/), the kernels, the scripts and CI.
fn source_files() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else { return };
        for entry in entries {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_str().unwrap_or("");
            if path.is_dir() {
                if !matches!(name, "target" | "data" | "corpus" | "artifacts") {
                    walk(&path, out);
                }
            } else if matches!(
                path.extension().and_then(|e| e.to_str()),
                Some("rs" | "glsl" | "comp" | "vert" | "frag" | "py" | "toml" | "sh")
            ) {
                out.push(path);
            }
        }
    }
    let mut files = Vec::new();
    for dir in ["src", "tests", "glsl", "scripts", "fuzz"] {
        walk(&repo().join(dir), &mut files);
    }
    files.push(repo().join(".ci/run"));
    files.retain(|path| !path.ends_with("tests/docs.rs"));
    files.sort();
    files
}

/// Each `docs/<page>.md` (with its `#anchor`, if any) that a line names, and whether it is
/// followed by `: Heading`, the old way of naming a section.
fn docs_references(line: &str) -> Vec<(String, bool)> {
    let mut found = Vec::new();
    for (at, _) in line.match_indices("docs/") {
        if line[..at].chars().next_back().is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '-') {
            continue;
        }
        let rest = &line[at..];
        let page_end =
            5 + rest[5..].find(|c: char| !(c.is_alphanumeric() || c == '_' || c == '-')).unwrap_or(rest.len() - 5);
        if !rest[page_end..].starts_with(".md") {
            continue;
        }
        let mut end = page_end + 3;
        if rest[end..].starts_with('#') {
            end += 1 + rest[end + 1..]
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == '-'))
                .unwrap_or(rest.len() - end - 1);
        }
        let after = &rest[end..];
        let old_style = after.starts_with(": ")
            && after[2..].chars().next().is_some_and(|c| c.is_uppercase() || c == '`' || c.is_lowercase());
        found.push((rest[..end].to_string(), old_style));
    }
    found
}

#[test]
fn docs_references_are_found() {
    assert_eq!(docs_references("//! Looks (docs/formats.md#looks)."), [("docs/formats.md#looks".to_string(), false)]);
    assert_eq!(docs_references("// see docs/shading.md, and mydocs/x.md"), [("docs/shading.md".to_string(), false)]);
    assert_eq!(docs_references("(docs/formats.md: Production renders)"), [("docs/formats.md".to_string(), true)]);
    assert_eq!(docs_references("docs/images/viewer.png"), []);
}

/// (b) Every `docs/<page>.md#<anchor>` the sources name resolves, and none names a section the
/// old way (`docs/formats.md: Looks`), which nothing could check.
#[test]
fn docs_references_in_sources_resolve() {
    let mut cache = BTreeMap::new();
    let mut problems = Vec::new();
    let mut checked = 0;
    for path in source_files() {
        let relative = path.strip_prefix(repo()).unwrap();
        let text = read(&path);
        for (i, line) in text.lines().enumerate() {
            for (reference, old_style) in docs_references(line) {
                checked += 1;
                let at = format!("{}:{}", relative.display(), i + 1);
                if old_style {
                    problems.push(format!(
                        "{at}: `{reference}: …` names a section in words: link its anchor, {reference}#…"
                    ));
                }
                // The reference is relative to the repository, as from a file at its root.
                if let Some(problem) = check_link(Path::new("README.md"), &reference, &mut cache) {
                    problems.push(format!("{at}: {problem}"));
                }
            }
        }
    }
    assert!(problems.is_empty(), "{} of {checked} references are broken:\n{}", problems.len(), problems.join("\n"));
    assert!(checked > 30, "only {checked} references found: is the scan broken?");
}

// ---------------------------------------------------------------------------------------------
// The README's commands
// ---------------------------------------------------------------------------------------------

/// Splits a command line into words as a shell would for plain words, single and double quotes
/// and backslashes. Anything else a shell would interpret (variables, globs, pipes,
/// redirection, command substitution, `~`) is refused: this test would not run it faithfully.
fn shell_words(command: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut word: Option<String> = None;
    let mut chars = command.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            ' ' | '\t' => {
                if let Some(w) = word.take() {
                    words.push(w);
                }
            }
            '\'' => {
                let w = word.get_or_insert_with(String::new);
                loop {
                    match chars.next() {
                        Some('\'') => break,
                        Some(c) => w.push(c),
                        None => panic!("unclosed ' in: {command}"),
                    }
                }
            }
            '"' => {
                let w = word.get_or_insert_with(String::new);
                loop {
                    match chars.next() {
                        Some('"') => break,
                        Some('\\') => match chars.next() {
                            Some(c @ ('"' | '\\' | '$' | '`')) => w.push(c),
                            Some(c) => {
                                w.push('\\');
                                w.push(c);
                            }
                            None => panic!("unclosed \" in: {command}"),
                        },
                        Some(c @ ('$' | '`')) => {
                            panic!("`{c}` inside quotes is not handled by tests/docs.rs: {command}")
                        }
                        Some(c) => w.push(c),
                        None => panic!("unclosed \" in: {command}"),
                    }
                }
            }
            '\\' => word.get_or_insert_with(String::new).push(chars.next().expect("a trailing backslash")),
            '$' | '`' | '|' | '&' | ';' | '<' | '>' | '(' | ')' | '*' | '?' | '[' | ']' | '{' | '}' => {
                panic!("`{c}` is shell syntax that tests/docs.rs does not handle: {command}")
            }
            '~' if word.is_none() => panic!("`~` is shell syntax that tests/docs.rs does not handle: {command}"),
            c => word.get_or_insert_with(String::new).push(c),
        }
    }
    words.extend(word);
    words
}

/// Removes a shell comment: a `#` that starts a word, outside quotes.
fn strip_comment(line: &str) -> &str {
    let mut quote = None;
    let mut previous = ' ';
    for (i, c) in line.char_indices() {
        match (quote, c) {
            (None, '\'' | '"') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            (None, '#') if previous == ' ' || previous == '\t' => return &line[..i],
            _ => {}
        }
        previous = c;
    }
    line
}

/// The shell commands of the README's code blocks (those marked sh, bash, shell or console,
/// or unmarked), with their line numbers: comments removed, continuations joined, prompts
/// (`$ `) dropped.
fn readme_commands() -> Vec<(usize, String)> {
    let (_, blocks) = split_code(&read(&repo().join("README.md")));
    let mut commands = Vec::new();
    for block in blocks {
        let language = block.info.split_whitespace().next().unwrap_or("");
        if !matches!(language, "" | "sh" | "bash" | "shell" | "console") {
            continue;
        }
        let mut pending: Option<(usize, String)> = None;
        for (i, line) in block.lines.iter().enumerate() {
            let line = line.trim();
            let line = line.strip_prefix("$ ").unwrap_or(line);
            let (start, mut text) = pending.take().unwrap_or((block.first_line + i, String::new()));
            let code = strip_comment(line).trim_end();
            if let Some(continued) = code.strip_suffix('\\') {
                text.push_str(continued);
                text.push(' ');
                pending = Some((start, text));
                continue;
            }
            text.push_str(code);
            let text = text.trim().to_string();
            if !text.is_empty() {
                commands.push((start, text));
            }
        }
        assert!(pending.is_none(), "README.md: a code block ends in a continued line");
    }
    commands
}

#[test]
fn shell_words_and_comments() {
    assert_eq!(
        shell_words(r#"cargo run --release -- render --out "a b.png" --set 'base_color=1,0,0' x\ y"#),
        ["cargo", "run", "--release", "--", "render", "--out", "a b.png", "--set", "base_color=1,0,0", "x y"]
    );
    assert_eq!(strip_comment("cargo test --release   # the whole suite"), "cargo test --release   ");
    assert_eq!(strip_comment("lookdev render --out 'a #1.png'"), "lookdev render --out 'a #1.png'");
    assert!(std::panic::catch_unwind(|| shell_words("lookdev render --out $HOME/x.png")).is_err());
    assert!(std::panic::catch_unwind(|| shell_words("lookdev render | head")).is_err());
}

/// The commands `.ci/run` runs, word by word (its lines outside comments).
fn ci_commands() -> Vec<Vec<String>> {
    read(&repo().join(".ci/run"))
        .lines()
        .map(|line| strip_comment(line).split_whitespace().map(str::to_string).collect::<Vec<_>>())
        .filter(|words| !words.is_empty())
        .collect()
}

/// `cargo run --release -- ARGS`: the built binary runs ARGS in an empty folder, with
/// validation on, and writes the file its `--out` names.
fn run_lookdev(line: usize, args: &[String]) {
    let dir = tempfile::tempdir().unwrap();
    let start = Instant::now();
    let output = Command::new(env!("CARGO_BIN_EXE_lookdev"))
        .args(args)
        .current_dir(dir.path())
        .env("LOOKDEV_VALIDATION", "1")
        .output()
        .unwrap();
    println!("README.md:{line}: lookdev {} took {:.1} s", args.join(" "), start.elapsed().as_secs_f64());
    assert_success(&output);
    let out = args
        .iter()
        .position(|a| a == "--out")
        .map(|i| args.get(i + 1).expect("--out without a value").clone())
        .or_else(|| args.iter().find_map(|a| a.strip_prefix("--out=").map(str::to_string)));
    if let Some(out) = out {
        let file = dir.path().join(&out);
        let size = std::fs::metadata(&file).map(|m| m.len()).unwrap_or(0);
        assert!(size > 0, "README.md:{line}: lookdev {} wrote no {out}", args.join(" "));
        if out.ends_with(".png") {
            let image = image::open(&file).unwrap_or_else(|e| panic!("README.md:{line}: {out}: {e}"));
            println!("README.md:{line}: {out}: {}×{}, {size} bytes", image.width(), image.height());
        }
    }
}

/// (c) Every command of the README runs as written, or is checked in a stated way:
/// - `cargo run --release -- ARGS` runs the built binary with ARGS ([`run_lookdev`]);
/// - `cargo test …` is what CI runs: `.ci/run` must run exactly that command (running it here
///   would run this test again).
///
/// A command of any other kind fails this test until it is handled here.
#[test]
fn readme_commands_run_as_written() {
    let commands = readme_commands();
    assert!(!commands.is_empty(), "README.md shows no commands");
    let ci = ci_commands();
    let mut ran = 0;
    let mut test_commands = 0;
    for (line, command) in commands {
        let words = shell_words(&command);
        let words: Vec<&str> = words.iter().map(String::as_str).collect();
        match words.as_slice() {
            ["cargo", "run", "--release", "--", args @ ..] => {
                let args: Vec<String> = args.iter().map(|a| a.to_string()).collect();
                run_lookdev(line, &args);
                ran += 1;
            }
            ["cargo", "test", ..] => {
                assert!(
                    ci.iter().any(|c| *c == words),
                    "README.md:{line}: `{command}` is the test command, but .ci/run does not run it (it runs: {:?})",
                    ci.iter().filter(|c| c.first().is_some_and(|w| w == "cargo")).collect::<Vec<_>>()
                );
                test_commands += 1;
            }
            _ => panic!(
                "README.md:{line}: `{command}` is a command tests/docs.rs does not know how to check: \
                 run it, or check it in a stated way, in readme_commands_run_as_written"
            ),
        }
    }
    assert!(ran > 0, "README.md shows no `cargo run --release -- …` command");
    assert_eq!(test_commands, 1, "README.md should show the one test command that CI runs");
}

/// The packages the README tells users to install (`apt-get install …`) are ones `.ci/run`
/// installs, so that what CI tests is what the README describes.
#[test]
fn readme_packages_are_what_ci_installs() {
    let readme = read(&repo().join("README.md"));
    let ci = read(&repo().join(".ci/run"));
    let ci_words: HashSet<&str> = ci.lines().flat_map(|l| strip_comment(l).split_whitespace()).collect();
    let mut packages = Vec::new();
    for (at, _) in readme.match_indices("apt-get install ") {
        let rest = &readme[at + "apt-get install ".len()..];
        let end = rest.find(['`', '\n']).unwrap_or(rest.len());
        packages.extend(rest[..end].split_whitespace().filter(|w| !w.starts_with('-')));
    }
    assert!(!packages.is_empty(), "README.md names no packages to install");
    for package in packages {
        assert!(ci_words.contains(package), "README.md asks for the package {package}, which .ci/run does not install");
    }
}

/// ... and every package `.ci/run` installs is one the README names, so that its prerequisites
/// are all a fresh machine needs (Blender and the X11 libraries were once left out).
#[test]
fn ci_packages_are_what_the_readme_names() {
    let readme = read(&repo().join("README.md"));
    let ci = read(&repo().join(".ci/run"));
    let list = ci.split_once("packages=(").and_then(|(_, rest)| rest.split_once(')')).map(|(list, _)| list);
    let list = list.expect(".ci/run lists its packages as packages=( … )");
    let packages: Vec<&str> = list.lines().flat_map(|l| strip_comment(l).split_whitespace()).collect();
    assert!(packages.len() > 5, "{packages:?}");
    let words: HashSet<&str> =
        readme.split_whitespace().map(|w| w.trim_matches(|c: char| "`(),.;:".contains(c))).collect();
    for package in packages {
        assert!(words.contains(package), ".ci/run installs {package}, which README.md does not name");
    }
}

/// A command shown inline in the README with its flags (`lookdev presets sheet --size 100 …`)
/// parses as written: the gallery's sheet command once lacked its required --out.
#[test]
fn readme_inline_commands_parse() {
    let (prose, _) = split_code(&read(&repo().join("README.md")));
    let mut checked = 0;
    for snippet in prose.split('`').skip(1).step_by(2) {
        let words: Vec<&str> = snippet.split_whitespace().collect();
        if words.first() != Some(&"lookdev") || !words.iter().any(|w| w.starts_with("--")) {
            continue;
        }
        let args = words.iter().map(std::ffi::OsString::from);
        if let Err(e) = lookdev::cli::parse(args) {
            panic!("README.md: `{snippet}` does not parse: {e}");
        }
        checked += 1;
    }
    assert!(checked > 0, "the README shows no inline command with flags");
}
