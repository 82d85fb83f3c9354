//! The shape of the code, as docs/architecture.md states it: within each crate
//! no two files import each other in a circle, no file grows past 600 lines and
//! no function past 120 without a written reason, and the orchestrator links no
//! window system. Each failure names the file, the lines and the function, so
//! the fix starts from the message.
//!
//! Reasons are markers a reader finds where they apply: a file's opening `//!`
//! comment has a line `//! Long file: <reason>`, a function has
//! `// Long function: <reason>` in the comments directly above it.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use syn::spanned::Spanned;
use syn::visit::Visit;
use twinray_tests::assert_none;
use twinray_tests::repo::{files_under, root};

const CRATES: [&str; 5] = ["common", "vk", "gl", "comparison", "tests"];
const MAX_FILE_LINES: usize = 600;
const MAX_FN_LINES: usize = 120;
const FILE_MARKER: &str = "//! Long file:";
const FN_MARKER: &str = "Long function:";

/// Every .rs file of a crate: its library or binary sources and its tests.
fn crate_files(krate: &str) -> Vec<PathBuf> {
    ["src", "tests", "benches", "examples"]
        .iter()
        .flat_map(|sub| files_under(&root().join(krate).join(sub), &["rs"]))
        .collect()
}

fn every_file() -> Vec<PathBuf> {
    CRATES.iter().flat_map(|c| crate_files(c)).collect()
}

fn relative(path: &Path) -> String {
    path.strip_prefix(root())
        .unwrap_or(path)
        .display()
        .to_string()
}

fn parse(path: &Path) -> (String, syn::File) {
    let text = std::fs::read_to_string(path).unwrap();
    let parsed = syn::parse_file(&text);
    (
        text,
        parsed.unwrap_or_else(|e| panic!("{} does not parse: {e}", relative(path))),
    )
}

/// The module path of a file of `src/` in its crate: `src/lib.rs` is the root
/// (empty), `src/a.rs` and `src/a/mod.rs` are `a`, `src/a/b.rs` is `a::b`.
/// Binaries beside a library (`main.rs`, `src/bin/`) are crates of their own
/// that reach the library by its name, never through `crate::`, so they are
/// left out; a crate with only `main.rs` has it as its root.
fn module_path(src: &Path, file: &Path, has_lib: bool) -> Option<Vec<String>> {
    let rel = file.strip_prefix(src).ok()?;
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    if parts.first().is_some_and(|p| p == "bin") {
        return None;
    }
    let last = parts.pop()?;
    match last.as_str() {
        "lib.rs" if parts.is_empty() => Some(parts),
        "main.rs" if parts.is_empty() => (!has_lib).then_some(parts),
        "mod.rs" => Some(parts),
        name => {
            parts.push(name.trim_end_matches(".rs").to_string());
            Some(parts)
        }
    }
}

/// One `use` or path in a file, resolved to an absolute module path.
struct Reference {
    path: Vec<String>,
    line: usize,
    /// `pub use`: a re-export other files may import through.
    reexport: bool,
    glob: bool,
}

/// Collects the `crate::`, `super::` and `self::` paths of one file, tracking
/// inline modules (`mod tests { use super::*; }` refers to the file itself).
struct Collector<'a> {
    file_module: &'a [String],
    inline: Vec<String>,
    found: Vec<Reference>,
}

impl Collector<'_> {
    fn here(&self) -> Vec<String> {
        let mut m = self.file_module.to_vec();
        m.extend(self.inline.iter().cloned());
        m
    }

    /// The absolute path of `segments` as written here, or None when it does not
    /// start in this crate (`std::`, another crate, a local name).
    fn absolute(&self, segments: &[String]) -> Option<Vec<String>> {
        let first = segments.first()?;
        let mut base = match first.as_str() {
            "crate" => Vec::new(),
            "self" | "super" => self.here(),
            _ => return None,
        };
        let mut rest = &segments[1..];
        if first == "super" {
            base.pop()?;
        }
        while rest.first().is_some_and(|s| s == "super") {
            base.pop()?;
            rest = &rest[1..];
        }
        base.extend(rest.iter().cloned());
        Some(base)
    }

    fn use_tree(&mut self, prefix: &mut Vec<String>, tree: &syn::UseTree, reexport: bool) {
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.use_tree(prefix, &p.tree, reexport);
                prefix.pop();
            }
            syn::UseTree::Name(n) => self.push_use(prefix, Some(n.ident.to_string()), n, reexport),
            syn::UseTree::Rename(r) => {
                self.push_use(prefix, Some(r.ident.to_string()), r, reexport)
            }
            syn::UseTree::Glob(g) => self.push_use(prefix, None, g, reexport),
            syn::UseTree::Group(g) => {
                for t in &g.items {
                    self.use_tree(prefix, t, reexport);
                }
            }
        }
    }

    fn push_use(
        &mut self,
        prefix: &[String],
        name: Option<String>,
        at: &dyn Spanned,
        reexport: bool,
    ) {
        let mut segments = prefix.to_vec();
        let glob = name.is_none();
        // `use super::{self, x}`: `self` names the prefix itself.
        if let Some(n) = name.filter(|n| n != "self") {
            segments.push(n);
        }
        if let Some(path) = self.absolute(&segments) {
            self.found.push(Reference {
                path,
                line: at.span().start().line,
                reexport,
                glob,
            });
        }
    }
}

impl<'ast> Visit<'ast> for Collector<'_> {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        // Unit tests may reach anywhere in their crate; only what ships counts.
        let test_only = m.attrs.iter().any(|a| {
            a.path().is_ident("cfg") && a.parse_args::<syn::Ident>().is_ok_and(|i| i == "test")
        });
        if m.content.is_some() && !test_only {
            self.inline.push(m.ident.to_string());
            syn::visit::visit_item_mod(self, m);
            self.inline.pop();
        }
    }

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        let reexport = matches!(u.vis, syn::Visibility::Public(_));
        // Only re-exports at the file's own level are seen from outside.
        let reexport = reexport && self.inline.is_empty();
        self.use_tree(&mut Vec::new(), &u.tree, reexport);
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        let segments: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
        // A bare `self`/`super` in an expression is a value or a single-segment
        // path, not a module reference.
        if segments.len() > 1 {
            if let Some(path) = self.absolute(&segments) {
                self.found.push(Reference {
                    path,
                    line: p.span().start().line,
                    reexport: false,
                    glob: false,
                });
            }
        }
        syn::visit::visit_path(self, p);
    }
}

struct Module {
    file: PathBuf,
    references: Vec<Reference>,
}

/// Which file module a path lands in, following `pub use` re-exports so that
/// importing `crate::scene::Scene` through a folder's `mod.rs` counts as
/// importing the file that defines it.
fn resolve(
    modules: &BTreeMap<Vec<String>, Module>,
    path: &[String],
    depth: usize,
) -> Option<Vec<String>> {
    let owner = (0..=path.len())
        .rev()
        .map(|n| &path[..n])
        .find(|p| modules.contains_key(*p))?
        .to_vec();
    let Some(name) = path.get(owner.len()) else {
        return Some(owner);
    };
    if depth < 8 {
        let module = &modules[&owner];
        let named = module.references.iter().filter(|r| r.reexport && !r.glob);
        for r in named {
            if r.path.last() == Some(name) {
                let mut through = r.path.clone();
                through.extend(path[owner.len() + 1..].iter().cloned());
                return resolve(modules, &through, depth + 1);
            }
        }
        let globs = module.references.iter().filter(|r| r.reexport && r.glob);
        for r in globs {
            let mut through = r.path.clone();
            through.extend(path[owner.len()..].iter().cloned());
            if let Some(target) = resolve(modules, &through, depth + 1) {
                if target != owner && target != r.path {
                    return Some(target);
                }
            }
        }
    }
    Some(owner)
}

/// The groups of modules that reach each other (strongly connected components)
/// with more than one member. A crate has a few dozen modules, so reachability
/// from every module is cheap and plain.
fn cycles(graph: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Vec<Vec<Vec<String>>> {
    let reach = |from: &Vec<String>| {
        let mut seen = BTreeSet::new();
        let mut todo = vec![from];
        while let Some(v) = todo.pop() {
            for w in graph.get(v).into_iter().flatten() {
                if seen.insert(w) {
                    todo.push(w);
                }
            }
        }
        seen
    };
    let reachable: BTreeMap<_, _> = graph.keys().map(|v| (v, reach(v))).collect();
    let mut found: Vec<Vec<Vec<String>>> = Vec::new();
    for (v, from_v) in &reachable {
        if found.iter().any(|c| c.contains(*v)) || !from_v.contains(v) {
            continue;
        }
        let component: Vec<_> = from_v
            .iter()
            .filter(|w| reachable.get(**w).is_some_and(|r| r.contains(v)))
            .map(|w| (*w).clone())
            .collect();
        if component.len() > 1 {
            found.push(component);
        }
    }
    found
}

/// The import cycles of one crate, each with the lines that close it.
fn crate_cycles(krate: &str) -> Vec<String> {
    let src = root().join(krate).join("src");
    let has_lib = src.join("lib.rs").is_file();
    let files = files_under(&src, &["rs"]);
    let mut modules = BTreeMap::new();
    for file in files {
        let Some(module) = module_path(&src, &file, has_lib) else {
            continue;
        };
        let (_, ast) = parse(&file);
        let mut collector = Collector {
            file_module: &module,
            inline: Vec::new(),
            found: Vec::new(),
        };
        collector.visit_file(&ast);
        let references = collector.found;
        modules.insert(module, Module { file, references });
    }
    // Edge a -> b with the first line of a that makes it.
    let mut graph: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    let mut evidence: HashMap<(Vec<String>, Vec<String>), (usize, String)> = HashMap::new();
    for (from, module) in &modules {
        let edges = graph.entry(from.clone()).or_default();
        for r in &module.references {
            let Some(to) = resolve(&modules, &r.path, 0) else {
                continue;
            };
            // A module reaching into itself, or the root only declaring its
            // children, is no import between files.
            if &to == from || to.is_empty() {
                continue;
            }
            edges.insert(to.clone());
            evidence
                .entry((from.clone(), to))
                .or_insert((r.line, r.path.join("::")));
        }
    }
    cycles(&graph)
        .into_iter()
        .map(|component| {
            let members: BTreeSet<_> = component.iter().cloned().collect();
            let mut lines = vec![format!(
                "{krate}: {} import each other in a circle:",
                component
                    .iter()
                    .map(|m| relative(&modules[m].file))
                    .collect::<Vec<_>>()
                    .join(", ")
            )];
            for from in &component {
                for to in graph[from].iter().filter(|t| members.contains(*t)) {
                    let (line, path) = &evidence[&(from.clone(), to.clone())];
                    let (a, b) = (relative(&modules[from].file), relative(&modules[to].file));
                    lines.push(format!("  {a}:{line} uses crate::{path} from {b}"));
                }
            }
            lines.join("\n")
        })
        .collect()
}

#[test]
fn no_import_cycle_between_the_files_of_a_crate() {
    let found: Vec<String> = CRATES.iter().flat_map(|c| crate_cycles(c)).collect();
    assert_none("import cycle(s); give each pair one direction (move what both need into a module both import)", &found);
}

#[test]
fn the_cycle_finder_sees_a_cycle() {
    let m = |s: &str| s.split("::").map(str::to_string).collect::<Vec<_>>();
    let mut graph = BTreeMap::new();
    graph.insert(m("a"), BTreeSet::from([m("b")]));
    graph.insert(m("b"), BTreeSet::from([m("c")]));
    graph.insert(m("c"), BTreeSet::from([m("a")]));
    graph.insert(m("d"), BTreeSet::from([m("a")]));
    assert_eq!(cycles(&graph), vec![vec![m("a"), m("b"), m("c")]]);
    graph.insert(m("c"), BTreeSet::new());
    assert!(cycles(&graph).is_empty());
}

#[test]
fn imports_are_resolved_through_super_and_reexports() {
    let ast: syn::File = syn::parse_quote! {
        use super::camera::Camera;
        pub use self::format::Scene;
        use crate::{gpu::{self, GpuScene}, limits};
        mod tests { use super::*; fn t() { crate::bvh::build(); } }
    };
    let module = vec!["scene".to_string()];
    let mut c = Collector {
        file_module: &module,
        inline: Vec::new(),
        found: Vec::new(),
    };
    c.visit_file(&ast);
    let paths: Vec<String> = c.found.iter().map(|r| r.path.join("::")).collect();
    assert_eq!(
        paths,
        [
            "camera::Camera",
            "scene::format::Scene",
            "gpu",
            "gpu::GpuScene",
            "limits",
            "scene",
            "bvh::build"
        ]
    );
}

#[test]
fn no_file_over_600_lines_without_a_reason() {
    let files = every_file();
    assert!(files.len() > 50, "only {} files found", files.len());
    let mut offenders = Vec::new();
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        let lines = text.lines().count();
        let reason = text
            .lines()
            .take_while(|l| l.starts_with("//!"))
            .find_map(|l| l.strip_prefix(FILE_MARKER))
            .is_some_and(|r| !r.trim().is_empty());
        if lines > MAX_FILE_LINES && !reason {
            offenders.push(format!("{}: {lines} lines", relative(&file)));
        }
    }
    assert_none(&format!("file(s) over {MAX_FILE_LINES} lines: split them, or open them with `{FILE_MARKER} <reason>`"), &offenders);
}

/// Every function with a body: free, in an impl, default in a trait, nested.
struct Functions<'a> {
    text: &'a [&'a str],
    owner: Vec<String>,
    found: Vec<(String, usize, usize, bool)>,
}

impl Functions<'_> {
    fn add(&mut self, ident: &syn::Ident, fn_token: &syn::token::Fn, block: &syn::Block) {
        let start = fn_token.span().start().line;
        let end = block.span().end().line;
        let mut name = self.owner.clone();
        name.push(ident.to_string());
        // The comment block directly above the fn (and its attributes) carries
        // the reason.
        let reasoned = self.text[..start.saturating_sub(1)]
            .iter()
            .rev()
            .map(|l| l.trim())
            .take_while(|l| l.starts_with("//") || l.starts_with("#[") || l.starts_with("#!["))
            .any(|l| {
                l.split_once(FN_MARKER)
                    .is_some_and(|(_, reason)| !reason.trim().is_empty())
            });
        self.found
            .push((name.join("::"), start, end - start + 1, reasoned));
    }
}

impl<'ast> Visit<'ast> for Functions<'_> {
    fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
        self.add(&f.sig.ident, &f.sig.fn_token, &f.block);
        syn::visit::visit_item_fn(self, f);
    }

    fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
        self.add(&f.sig.ident, &f.sig.fn_token, &f.block);
        syn::visit::visit_impl_item_fn(self, f);
    }

    fn visit_trait_item_fn(&mut self, f: &'ast syn::TraitItemFn) {
        if let Some(block) = &f.default {
            self.add(&f.sig.ident, &f.sig.fn_token, block);
        }
        syn::visit::visit_trait_item_fn(self, f);
    }

    fn visit_item_impl(&mut self, i: &'ast syn::ItemImpl) {
        let owner = match &*i.self_ty {
            syn::Type::Path(p) => p.path.segments.last().map(|s| s.ident.to_string()),
            _ => None,
        };
        self.owner.push(owner.unwrap_or_else(|| "?".into()));
        syn::visit::visit_item_impl(self, i);
        self.owner.pop();
    }
}

fn functions(text: &str, ast: &syn::File) -> Vec<(String, usize, usize, bool)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut f = Functions {
        text: &lines,
        owner: Vec::new(),
        found: Vec::new(),
    };
    f.visit_file(ast);
    f.found
}

#[test]
fn no_function_over_120_lines_without_a_reason() {
    let mut offenders = Vec::new();
    let mut checked = 0;
    for file in every_file() {
        let (text, ast) = parse(&file);
        for (name, line, length, reasoned) in functions(&text, &ast) {
            checked += 1;
            if length > MAX_FN_LINES && !reasoned {
                let at = relative(&file);
                offenders.push(format!("{at}:{line}: fn {name} is {length} lines"));
            }
        }
    }
    assert!(checked > 300, "only {checked} functions found");
    assert_none(&format!("function(s) over {MAX_FN_LINES} lines: split them, or put `// {FN_MARKER} <reason>` directly above"), &offenders);
}

#[test]
fn the_function_measure_counts_lines_and_sees_the_marker() {
    let text = "impl A {\n    // Long function: one table.\n    #[allow(x)]\n    fn a() {\n        1;\n    }\n}\n\nfn b() {}\n";
    let ast = syn::parse_file(text).unwrap();
    assert_eq!(
        functions(text, &ast),
        [
            ("A::a".to_string(), 4, 3, true),
            ("b".to_string(), 9, 1, false)
        ]
    );
}

/// The orchestrator and everything it links must not pull in a window system:
/// only the apps open windows.
#[test]
fn the_orchestrator_links_no_winit() {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let output = std::process::Command::new(&cargo)
        .args(["tree", "--offline", "-p", "twinray", "-e", "normal"])
        .current_dir(root())
        .output();
    let output = match output {
        Ok(o) if o.status.success() => o,
        Ok(o) => panic!(
            "`cargo tree -p twinray -e normal` failed:\n{}",
            String::from_utf8_lossy(&o.stderr)
        ),
        Err(e) => panic!(
            "cannot run `{cargo} tree` to list the orchestrator's dependencies ({e}); \
             this test needs cargo on PATH or in $CARGO"
        ),
    };
    let tree = String::from_utf8_lossy(&output.stdout);
    let lines: Vec<&str> = tree.lines().collect();
    // Each window-system line with the chain of dependents above it.
    let depth = |l: &str| l.find(|c: char| c.is_alphanumeric()).unwrap_or(0);
    let mut chains = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        if line.contains(" winit v") || line.contains(" glutin-winit v") {
            let mut chain = vec![*line];
            for above in lines[..i].iter().rev() {
                if depth(above) < depth(chain.last().unwrap()) {
                    chain.push(above);
                }
            }
            chains.push(chain.into_iter().rev().collect::<Vec<_>>().join("\n"));
        }
    }
    assert_none("`cargo tree -p twinray -e normal` lists a window system; keep the windowed code behind the apps' feature", &chains);
}
