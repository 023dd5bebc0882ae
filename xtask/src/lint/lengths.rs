//! Lengths: functions (parsed with `syn`, so strings, comments and macros cannot mislead the
//! count) and files.

use std::path::Path;

use syn::spanned::Spanned;

use super::{Finding, MAX_FILE_LINES, MAX_FUNCTION_LINES};

/// The functions of `text` (free, in `impl` and `trait` blocks, in inline modules, and
/// functions nested in those) longer than the house allows.
pub fn long_functions(file: &Path, text: &str) -> Result<Vec<Finding>, String> {
    let parsed =
        syn::parse_file(text).map_err(|e| format!("{}: cannot parse: {e}", file.display()))?;
    let mut found = Vec::new();
    let mut visitor = LongFunctions {
        file,
        found: &mut found,
    };
    syn::visit::visit_file(&mut visitor, &parsed);
    Ok(found)
}

/// The file itself, when it is over the house's length.
pub fn long_file(file: &Path, text: &str) -> Option<Finding> {
    let lines = text.lines().count();
    (lines > MAX_FILE_LINES).then(|| {
        format!(
            "{}: {lines} lines, over {MAX_FILE_LINES}: split it by its parts",
            file.display()
        )
    })
}

struct LongFunctions<'a> {
    file: &'a Path,
    found: &'a mut Vec<Finding>,
}

impl LongFunctions<'_> {
    /// Records `name` when its span, attributes and doc comments aside, is too long.
    fn check(&mut self, name: &syn::Ident, signature: &syn::Signature, body: &syn::Block) {
        let first = signature.span().start().line;
        let last = body.span().end().line;
        let lines = last + 1 - first;
        if lines > MAX_FUNCTION_LINES {
            self.found.push(format!(
                "{}:{first}: fn {name} is {lines} lines, over {MAX_FUNCTION_LINES}: read it as named steps",
                self.file.display()
            ));
        }
    }
}

impl<'ast> syn::visit::Visit<'ast> for LongFunctions<'_> {
    fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
        self.check(&f.sig.ident, &f.sig, &f.block);
        syn::visit::visit_item_fn(self, f);
    }

    fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
        self.check(&f.sig.ident, &f.sig, &f.block);
        syn::visit::visit_impl_item_fn(self, f);
    }

    fn visit_trait_item_fn(&mut self, f: &'ast syn::TraitItemFn) {
        if let Some(body) = &f.default {
            self.check(&f.sig.ident, &f.sig, body);
        }
        syn::visit::visit_trait_item_fn(self, f);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn function_of(lines: usize) -> String {
        let body: String = (0..lines - 2)
            .map(|i| format!("    let _x{i} = {i};\n"))
            .collect();
        format!("/// Doc.\n#[inline]\nfn f() {{\n{body}}}\n")
    }

    #[test]
    fn a_function_is_counted_from_fn_to_its_brace() {
        let path = Path::new("a.rs");
        assert!(long_functions(path, &function_of(100)).unwrap().is_empty());
        let found = long_functions(path, &function_of(101)).unwrap();
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(found[0].contains("a.rs:3: fn f is 101 lines"), "{found:?}");
    }

    #[test]
    fn methods_trait_defaults_and_strings_are_seen_through() {
        let long = function_of(120).replace("fn f()", "fn g(&self)");
        let text = format!(
            "impl S {{\n{long}}}\ntrait T {{\n{}}}\nconst S: &str = \"fn h() {{\";\n",
            long.replace("fn g", "fn t")
        );
        let found = long_functions(Path::new("b.rs"), &text).unwrap();
        let names: Vec<bool> = ["fn g is 120", "fn t is 120"]
            .iter()
            .map(|n| found.iter().any(|f| f.contains(n)))
            .collect();
        assert_eq!((found.len(), names), (2, vec![true, true]), "{found:?}");
    }
}
