//! Circles of modules inside one crate: module `a` names something of module `b` and `b`,
//! through any chain, names something of `a`. A module's own ancestors are left out (a child
//! that takes a type from its parent, which declares and re-exports it, is the usual Rust
//! layout and not a circle), so what is found is a circle among siblings or cousins. Test
//! modules (`#[cfg(test)]`) are left out too.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use super::Finding;

/// A module's path inside its crate: `[]` for the root, `["refine", "fvar"]` and so on.
type ModulePath = Vec<String>;

/// The circles among the modules of the crate whose sources are `files` (under `src`).
pub fn module_circles(root: &Path, src: &Path, files: &[PathBuf]) -> Result<Vec<Finding>, String> {
    let modules: BTreeMap<ModulePath, &PathBuf> =
        files.iter().map(|f| (module_of(src, f), f)).collect();
    let known: BTreeSet<&ModulePath> = modules.keys().collect();
    let mut edges: BTreeMap<&ModulePath, BTreeSet<ModulePath>> = BTreeMap::new();
    for (module, file) in &modules {
        let text = std::fs::read_to_string(file)
            .map_err(|e| format!("{}: cannot read: {e}", file.display()))?;
        let parsed =
            syn::parse_file(&text).map_err(|e| format!("{}: cannot parse: {e}", file.display()))?;
        let mut paths = NamedPaths::default();
        syn::visit::visit_file(&mut paths, &parsed);
        let targets = paths
            .0
            .iter()
            .filter_map(|p| resolve(module, p, &known))
            .filter(|t| !module.starts_with(t))
            .collect();
        edges.insert(module, targets);
    }
    let shown = |m: &ModulePath| {
        let f = modules[m];
        f.strip_prefix(root).unwrap_or(f).display().to_string()
    };
    Ok(strongly_connected(&edges)
        .into_iter()
        .filter(|c| c.len() > 1)
        .map(|c| {
            let names: Vec<String> = c.iter().map(|m| shown(m)).collect();
            format!(
                "module circle: {} (each names the next, through some chain): move what they share below them",
                names.join(", ")
            )
        })
        .collect())
}

/// The module a file holds: `src/lib.rs` the root, `src/a/mod.rs` and `src/a.rs` module `a`.
fn module_of(src: &Path, file: &Path) -> ModulePath {
    let relative = file.strip_prefix(src).unwrap_or(file).with_extension("");
    let mut parts: ModulePath = relative
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if parts.len() == 1 && (parts[0] == "lib" || parts[0] == "main") {
        parts.clear();
    }
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    parts
}

/// The deepest module of this crate that `path` (as written in `module`) reaches, or `None`
/// where it names another crate.
fn resolve(
    module: &ModulePath,
    path: &[String],
    known: &BTreeSet<&ModulePath>,
) -> Option<ModulePath> {
    let (mut at, rest) = match path.first().map(String::as_str) {
        Some("crate") => (Vec::new(), &path[1..]),
        Some("self") => (module.clone(), &path[1..]),
        Some("super") => {
            let supers = path.iter().take_while(|s| *s == "super").count();
            let keep = module.len().checked_sub(supers)?;
            (module[..keep].to_vec(), &path[supers..])
        }
        Some(first) => {
            // A bare path names a child module declared here, or something outside.
            let mut child = module.clone();
            child.push(first.to_string());
            if !known.contains(&child) {
                return None;
            }
            (module.clone(), path)
        }
        None => return None,
    };
    for segment in rest {
        at.push(segment.clone());
        if !known.contains(&at) {
            at.pop();
            break;
        }
    }
    Some(at)
}

/// Every path a file writes: in `use` trees (flattened) and in types and expressions.
#[derive(Default)]
struct NamedPaths(Vec<Vec<String>>);

impl NamedPaths {
    fn flatten(&mut self, prefix: &mut Vec<String>, tree: &syn::UseTree) {
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.flatten(prefix, &p.tree);
                prefix.pop();
            }
            syn::UseTree::Name(n) => self.push_with(prefix, &n.ident),
            syn::UseTree::Rename(r) => self.push_with(prefix, &r.ident),
            syn::UseTree::Glob(_) => self.0.push(prefix.clone()),
            syn::UseTree::Group(g) => g.items.iter().for_each(|t| self.flatten(prefix, t)),
        }
    }

    fn push_with(&mut self, prefix: &[String], last: &syn::Ident) {
        let mut path = prefix.to_vec();
        path.push(last.to_string());
        self.0.push(path);
    }
}

/// Whether an item is compiled for tests only: a test module takes from anywhere, and
/// is no part of the crate's layering.
fn is_test_only(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| match &a.meta {
        syn::Meta::List(list) => list.path.is_ident("cfg") && list.tokens.to_string() == "test",
        _ => false,
    })
}

impl<'ast> syn::visit::Visit<'ast> for NamedPaths {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if !is_test_only(&m.attrs) {
            syn::visit::visit_item_mod(self, m);
        }
    }

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        self.flatten(&mut Vec::new(), &u.tree);
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        self.0
            .push(p.segments.iter().map(|s| s.ident.to_string()).collect());
        syn::visit::visit_path(self, p);
    }
}

/// Tarjan's strongly connected components (Tarjan 1972), iterative over a small graph.
fn strongly_connected<'a>(
    edges: &BTreeMap<&'a ModulePath, BTreeSet<ModulePath>>,
) -> Vec<Vec<&'a ModulePath>> {
    let nodes: Vec<&ModulePath> = edges.keys().copied().collect();
    let index_of: BTreeMap<&ModulePath, usize> =
        nodes.iter().enumerate().map(|(i, m)| (*m, i)).collect();
    let next: Vec<Vec<usize>> = nodes
        .iter()
        .map(|m| {
            edges[m]
                .iter()
                .filter_map(|t| index_of.get(t).copied())
                .collect()
        })
        .collect();
    let mut tarjan = Tarjan::new(nodes.len());
    for start in 0..nodes.len() {
        if tarjan.index[start].is_none() {
            tarjan.visit(start, &next);
        }
    }
    tarjan
        .components
        .into_iter()
        .map(|c| c.into_iter().map(|i| nodes[i]).collect())
        .collect()
}

struct Tarjan {
    index: Vec<Option<usize>>,
    low: Vec<usize>,
    on_stack: Vec<bool>,
    stack: Vec<usize>,
    counter: usize,
    components: Vec<Vec<usize>>,
}

impl Tarjan {
    fn new(n: usize) -> Self {
        Tarjan {
            index: vec![None; n],
            low: vec![0; n],
            on_stack: vec![false; n],
            stack: Vec::new(),
            counter: 0,
            components: Vec::new(),
        }
    }

    /// Recursive: a crate has tens of modules, not thousands.
    fn visit(&mut self, v: usize, next: &[Vec<usize>]) {
        self.index[v] = Some(self.counter);
        self.low[v] = self.counter;
        self.counter += 1;
        self.stack.push(v);
        self.on_stack[v] = true;
        for &w in &next[v] {
            match self.index[w] {
                None => {
                    self.visit(w, next);
                    self.low[v] = self.low[v].min(self.low[w]);
                }
                Some(iw) if self.on_stack[w] => self.low[v] = self.low[v].min(iw),
                Some(_) => {}
            }
        }
        if Some(self.low[v]) == self.index[v] {
            let mut component = Vec::new();
            while let Some(w) = self.stack.pop() {
                self.on_stack[w] = false;
                component.push(w);
                if w == v {
                    break;
                }
            }
            self.components.push(component);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circles_of(files: &[(&str, &str)]) -> Vec<Finding> {
        let dir = std::env::temp_dir().join(format!("xtask-lint-{}", std::process::id()));
        let src = dir.join("src");
        let mut paths = Vec::new();
        for (name, text) in files {
            let path = src.join(name);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(&path, text).unwrap();
            paths.push(path);
        }
        let found = module_circles(&dir, &src, &paths).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        found
    }

    #[test]
    fn siblings_that_name_each_other_are_a_circle_and_a_parent_is_not() {
        let lib = "mod a; mod b; mod c; pub struct Root;";
        let a = "use crate::b::B; pub struct A; fn f(_: crate::Root) {}";
        let circle = circles_of(&[
            ("lib.rs", lib),
            ("a.rs", a),
            ("b.rs", "pub struct B; fn g(_: super::a::A) {}"),
            ("c.rs", ""),
        ]);
        assert_eq!(circle.len(), 1, "{circle:?}");
        assert!(
            circle[0].contains("src/a.rs, src/b.rs") || circle[0].contains("src/b.rs, src/a.rs"),
            "{circle:?}"
        );
        let line = circles_of(&[
            ("lib.rs", lib),
            ("a.rs", a),
            ("b.rs", "pub struct B; use crate::c;"),
            ("c.rs", "use super::Root;"),
        ]);
        assert!(line.is_empty(), "{line:?}");
    }
}
