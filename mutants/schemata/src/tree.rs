//! The crate's module tree read file by file, and put back together as one file with
//! every module inline.

use crate::Error;
use std::path::{Path, PathBuf};
use syn::{Attribute, Item};

/// A source file of the crate.
pub(crate) struct SourceFile {
    /// Relative to the source root: `lib.rs`, `slave/stack.rs`.
    pub rel: String,
    pub path: PathBuf,
    pub ast: syn::File,
}

/// The crate: its files in the order they are reached from `lib.rs`, depth first.
pub(crate) struct CrateTree {
    pub files: Vec<SourceFile>,
}

/// `#[cfg(test)]` or `#[cfg(kani)]`: items the copy leaves out.
pub(crate) fn is_test_only(attrs: &[Attribute]) -> bool {
    attrs
        .iter()
        .any(|a| a.path().is_ident("cfg") && a.parse_args::<syn::Ident>().is_ok_and(|i| i == "test" || i == "kani"))
}

fn item_attrs(item: &Item) -> Option<&Vec<Attribute>> {
    Some(match item {
        Item::Const(i) => &i.attrs,
        Item::Enum(i) => &i.attrs,
        Item::ExternCrate(i) => &i.attrs,
        Item::Fn(i) => &i.attrs,
        Item::ForeignMod(i) => &i.attrs,
        Item::Impl(i) => &i.attrs,
        Item::Macro(i) => &i.attrs,
        Item::Mod(i) => &i.attrs,
        Item::Static(i) => &i.attrs,
        Item::Struct(i) => &i.attrs,
        Item::Trait(i) => &i.attrs,
        Item::TraitAlias(i) => &i.attrs,
        Item::Type(i) => &i.attrs,
        Item::Union(i) => &i.attrs,
        Item::Use(i) => &i.attrs,
        _ => return None,
    })
}

/// Drop the test-only items of `items`, at every depth of inline modules.
fn drop_test_only(items: &mut Vec<Item>) {
    items.retain(|i| !item_attrs(i).is_some_and(|a| is_test_only(a)));
    for item in items.iter_mut() {
        match item {
            Item::Mod(m) => {
                if let Some((_, inner)) = m.content.as_mut() {
                    drop_test_only(inner);
                }
            }
            Item::Impl(i) => i.items.retain(|ii| match ii {
                syn::ImplItem::Fn(f) => !is_test_only(&f.attrs),
                syn::ImplItem::Const(c) => !is_test_only(&c.attrs),
                _ => true,
            }),
            _ => {}
        }
    }
}

fn parse(path: &Path) -> Result<syn::File, Error> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Read { path: path.into(), source })?;
    syn::parse_file(&text).map_err(|source| Error::Parse { path: path.into(), source })
}

/// Where the children of the module in `rel` live: beside `lib.rs` and `mod.rs`, in a
/// folder of the module's name otherwise.
fn children_dir(rel: &str) -> String {
    let (dir, name) = match rel.rsplit_once('/') {
        Some((d, n)) => (format!("{d}/"), n),
        None => (String::new(), rel),
    };
    if name == "lib.rs" || name == "mod.rs" {
        dir
    } else {
        format!("{dir}{}/", name.trim_end_matches(".rs"))
    }
}

/// Read the crate under `src` from `lib.rs`.
pub(crate) fn load(src: &Path) -> Result<CrateTree, Error> {
    let mut files = Vec::new();
    load_file(src, "lib.rs", &mut files)?;
    Ok(CrateTree { files })
}

fn load_file(src: &Path, rel: &str, files: &mut Vec<SourceFile>) -> Result<(), Error> {
    let path = src.join(rel);
    let mut ast = parse(&path)?;
    drop_test_only(&mut ast.items);
    let dir = children_dir(rel);
    let mut children = Vec::new();
    for item in &ast.items {
        if let Item::Mod(m) = item {
            if m.content.is_some() {
                continue;
            }
            if m.attrs.iter().any(|a| a.path().is_ident("path")) {
                return Err(Error::PathAttribute { path, module: m.ident.to_string() });
            }
            let name = m.ident.to_string();
            let candidates = [format!("{dir}{name}.rs"), format!("{dir}{name}/mod.rs")];
            let Some(child) = candidates.iter().find(|c| src.join(c).is_file()) else {
                return Err(Error::NoModuleFile { path, module: name, tried: candidates.join(", ") });
            };
            children.push(child.clone());
        }
    }
    files.push(SourceFile { rel: rel.to_string(), path, ast });
    for child in children {
        load_file(src, &child, files)?;
    }
    Ok(())
}

/// One file: every `mod name;` replaced by `mod name { ... }` with the child's items
/// and its inner attributes (its `//!` documentation among them). The root's inner
/// attributes are left to the file that includes the copy.
pub(crate) fn inline(tree: CrateTree) -> syn::File {
    let mut files = tree.files.into_iter();
    let Some(root) = files.next() else {
        return syn::File { shebang: None, attrs: Vec::new(), items: Vec::new() };
    };
    let mut rest: Vec<SourceFile> = files.collect();
    let mut ast = root.ast;
    fill(&root.rel, &mut ast.items, &mut rest);
    ast.attrs.clear();
    ast
}

fn fill(rel: &str, items: &mut [Item], rest: &mut Vec<SourceFile>) {
    let dir = children_dir(rel);
    for item in items.iter_mut() {
        let Item::Mod(m) = item else { continue };
        if m.content.is_some() {
            continue;
        }
        let name = m.ident.to_string();
        let candidates = [format!("{dir}{name}.rs"), format!("{dir}{name}/mod.rs")];
        let Some(pos) = rest.iter().position(|f| candidates.contains(&f.rel)) else { continue };
        let child = rest.remove(pos);
        let mut child_items = child.ast.items;
        fill(&child.rel, &mut child_items, rest);
        m.attrs.extend(child.ast.attrs);
        m.content = Some((Default::default(), child_items));
        m.semi = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn children_of_a_module_file_live_in_its_folder() {
        assert_eq!(children_dir("lib.rs"), "");
        assert_eq!(children_dir("slave/mod.rs"), "slave/");
        assert_eq!(children_dir("slave.rs"), "slave/");
        assert_eq!(children_dir("slave/execute/mod.rs"), "slave/execute/");
        assert_eq!(children_dir("slave/fields.rs"), "slave/fields/");
    }

    #[test]
    fn test_only_items_are_recognised() {
        let f: syn::File = syn::parse_quote! {
            #[cfg(test)] mod tests {}
            #[cfg(kani)] fn proof() {}
            #[cfg(not(test))] fn kept() {}
            fn also_kept() {}
        };
        let mut items = f.items;
        drop_test_only(&mut items);
        assert_eq!(items.len(), 2);
    }
}
