//! The values a function's body is replaced with, by its return type, as cargo-mutants
//! chooses them (27.x): `()`; `true`, `false`; `0`, `1` (and `-1` signed); `0.0`,
//! `1.0`, `-1.0`; `None` and `Some(v)`; `Ok(v)`; `""` and `"xyzzy"`; tuples of every
//! combination; `[v; N]`; `Default::default()` for other named types. A value is only
//! generated where it is known to compile in a `no_std` copy: named types only where
//! the crate derives or implements `Default` for them; no references but `&str`
//! (cargo-mutants leaks a `Box`, which needs an allocator); no `impl Trait`.

use crate::tree::CrateTree;
use proc_macro2::TokenStream;
use quote::quote;
use std::collections::BTreeSet;
use syn::visit::{self, Visit};

/// The types of the crate with a `Default`: derived or implemented.
pub(crate) fn types_with_default(tree: &CrateTree) -> BTreeSet<String> {
    let mut find = FindDefault::default();
    for f in &tree.files {
        find.visit_file(&f.ast);
    }
    find.0
}

#[derive(Default)]
struct FindDefault(BTreeSet<String>);

impl FindDefault {
    fn derives(&mut self, attrs: &[syn::Attribute], ident: &syn::Ident) {
        for a in attrs.iter().filter(|a| a.path().is_ident("derive")) {
            let mut has = false;
            let _ = a.parse_nested_meta(|m| {
                has |= m.path.is_ident("Default");
                Ok(())
            });
            if has {
                self.0.insert(ident.to_string());
            }
        }
    }
}

impl<'ast> Visit<'ast> for FindDefault {
    fn visit_item_struct(&mut self, i: &'ast syn::ItemStruct) {
        self.derives(&i.attrs, &i.ident);
        visit::visit_item_struct(self, i);
    }
    fn visit_item_enum(&mut self, i: &'ast syn::ItemEnum) {
        self.derives(&i.attrs, &i.ident);
        visit::visit_item_enum(self, i);
    }
    fn visit_item_impl(&mut self, i: &'ast syn::ItemImpl) {
        let is_default =
            i.trait_.as_ref().is_some_and(|(_, p, _)| p.segments.last().is_some_and(|s| s.ident == "Default"));
        if let (true, Some(name)) = (is_default, type_ident(&i.self_ty)) {
            self.0.insert(name);
        }
        visit::visit_item_impl(self, i);
    }
}

/// A value cargo-mutants puts in place of a body: its text as cargo-mutants writes
/// it, and the code, or why no code known to compile is generated.
#[derive(Debug, Clone)]
pub(crate) struct Candidate {
    pub text: String,
    pub code: Result<TokenStream, &'static str>,
}

fn known(code: TokenStream) -> Candidate {
    Candidate { text: crate::names::compact(&code), code: Ok(code) }
}

fn unknown(text: &str, why: &'static str) -> Candidate {
    Candidate { text: text.to_string(), code: Err(why) }
}

/// Wrap every candidate: `wrap(code)` and the text `before` + text + `after`.
fn wrapped(
    inner: Vec<Candidate>,
    before: &str,
    after: &str,
    wrap: impl Fn(TokenStream) -> TokenStream,
) -> Vec<Candidate> {
    inner
        .into_iter()
        .map(|c| Candidate { text: format!("{before}{}{after}", c.text), code: c.code.map(&wrap) })
        .collect()
}

/// What a function's values are.
pub(crate) enum Values {
    /// `()`: the body replaced by nothing.
    Unit,
    Some(Vec<Candidate>),
    /// cargo-mutants makes no value (`!`).
    None,
}

/// The values for a return type; `self_ty` is the impl's type, for `Self`.
pub(crate) fn values(ret: &syn::ReturnType, self_ty: Option<&syn::Type>, defaults: &BTreeSet<String>) -> Values {
    match ret {
        syn::ReturnType::Default => Values::Unit,
        syn::ReturnType::Type(_, ty) => match &**ty {
            syn::Type::Never(_) => Values::None,
            syn::Type::Tuple(t) if t.elems.is_empty() => Values::Unit,
            ty => Values::Some(of_type(ty, self_ty, defaults)),
        },
    }
}

const SIGNED: [&str; 6] = ["i8", "i16", "i32", "i64", "i128", "isize"];
const UNSIGNED: [&str; 6] = ["u8", "u16", "u32", "u64", "u128", "usize"];
const NO_ALLOCATOR: &str = "a reference: cargo-mutants leaks a Box, which a no_std copy has no allocator for";

fn of_type(ty: &syn::Type, self_ty: Option<&syn::Type>, defaults: &BTreeSet<String>) -> Vec<Candidate> {
    match ty {
        syn::Type::Paren(p) => of_type(&p.elem, self_ty, defaults),
        syn::Type::Group(g) => of_type(&g.elem, self_ty, defaults),
        syn::Type::Tuple(t) if t.elems.is_empty() => vec![known(quote!(()))],
        syn::Type::Tuple(t) => {
            let mut combos: Vec<Vec<Candidate>> = vec![Vec::new()];
            for elem in &t.elems {
                let vs = of_type(elem, self_ty, defaults);
                combos = combos
                    .into_iter()
                    .flat_map(|prefix| {
                        vs.iter().map(move |v| {
                            let mut p = prefix.clone();
                            p.push(v.clone());
                            p
                        })
                    })
                    .collect();
            }
            combos
                .into_iter()
                .map(|c| {
                    let text = format!("({})", c.iter().map(|x| x.text.as_str()).collect::<Vec<_>>().join(", "));
                    let code: Result<Vec<TokenStream>, &'static str> = c.into_iter().map(|x| x.code).collect();
                    Candidate { text, code: code.map(|parts| quote!((#(#parts),*))) }
                })
                .collect()
        }
        syn::Type::Array(a) => {
            let len = &a.len;
            let n = crate::names::compact(len);
            wrapped(of_type(&a.elem, self_ty, defaults), "[", &format!("; {n}]"), |v| quote!([#v; #len]))
        }
        syn::Type::Reference(r) => match &*r.elem {
            syn::Type::Path(p) if p.path.is_ident("str") && r.mutability.is_none() => {
                vec![known(quote!("")), known(quote!("xyzzy"))]
            }
            syn::Type::Slice(s) => {
                let mut v = vec![unknown("Vec::leak(Vec::new())", NO_ALLOCATOR)];
                v.extend(
                    of_type(&s.elem, self_ty, defaults)
                        .into_iter()
                        .map(|c| unknown(&format!("Vec::leak(vec![{}])", c.text), NO_ALLOCATOR)),
                );
                v
            }
            elem => of_type(elem, self_ty, defaults)
                .into_iter()
                .map(|c| unknown(&format!("Box::leak(Box::new({}))", c.text), NO_ALLOCATOR))
                .collect(),
        },
        syn::Type::ImplTrait(_) => {
            let why = "`impl Trait`: two branches cannot return different types";
            vec![unknown("::std::iter::empty()", why), unknown("::std::iter::once(Default::default())", why)]
        }
        syn::Type::Path(p) if p.qself.is_none() => {
            let Some(last) = p.path.segments.last() else { return Vec::new() };
            let name = last.ident.to_string();
            let args: Vec<&syn::Type> = match &last.arguments {
                syn::PathArguments::AngleBracketed(a) => a
                    .args
                    .iter()
                    .filter_map(|g| match g {
                        syn::GenericArgument::Type(t) => Some(t),
                        _ => None,
                    })
                    .collect(),
                _ => Vec::new(),
            };
            if p.path.segments.len() == 1 && args.is_empty() {
                if name == "bool" {
                    return vec![known(quote!(true)), known(quote!(false))];
                }
                if UNSIGNED.contains(&name.as_str()) {
                    return vec![known(quote!(0)), known(quote!(1))];
                }
                if SIGNED.contains(&name.as_str()) {
                    return vec![known(quote!(0)), known(quote!(1)), known(quote!(-1))];
                }
                if name == "f32" || name == "f64" {
                    return vec![known(quote!(0.0)), known(quote!(1.0)), known(quote!(-1.0))];
                }
            }
            match (name.as_str(), args.as_slice()) {
                ("Option", [t]) => {
                    let mut v = vec![known(quote!(None))];
                    v.extend(wrapped(of_type(t, self_ty, defaults), "Some(", ")", |x| quote!(Some(#x))));
                    v
                }
                ("Result", [t, ..]) => wrapped(of_type(t, self_ty, defaults), "Ok(", ")", |x| quote!(Ok(#x))),
                // `fmt::Result` and the like: a Result of `()`.
                ("Result", []) => vec![known(quote!(Ok(Default::default())))],
                ("Self", []) => match self_ty.and_then(type_ident) {
                    Some(n) if defaults.contains(&n) => vec![known(quote!(Default::default()))],
                    _ => vec![unknown("Default::default()", "Self without a Default")],
                },
                // A generic type of the crate: cargo-mutants guesses constructors.
                (_, [_, ..]) => {
                    let why = "a generic type: cargo-mutants guesses its constructors";
                    ["new()", "from_iter([Default::default()])", "new(Default::default())", "from(Default::default())"]
                        .iter()
                        .map(|c| unknown(&format!("{name}::{c}"), why))
                        .collect()
                }
                _ if defaults.contains(&name) => vec![known(quote!(Default::default()))],
                _ => vec![unknown("Default::default()", "a type without a Default")],
            }
        }
        _ => vec![unknown("Default::default()", "a type cargo-mutants has no value for")],
    }
}

fn type_ident(ty: &syn::Type) -> Option<String> {
    match ty {
        syn::Type::Path(p) => p.path.segments.last().map(|s| s.ident.to_string()),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vals(ret: syn::ReturnType) -> Vec<String> {
        let defaults: BTreeSet<String> = ["Settings".to_string()].into();
        match values(&ret, None, &defaults) {
            Values::Some(v) => v
                .iter()
                .map(|c| match &c.code {
                    Ok(_) => c.text.clone(),
                    Err(why) => format!("unknown {}: {why}", c.text),
                })
                .collect(),
            Values::Unit => vec!["unit".into()],
            Values::None => vec![],
        }
    }

    #[test]
    fn values_are_cargo_mutants_values() {
        assert_eq!(vals(syn::parse_quote!(-> i64)), ["0", "1", "-1"]);
        assert_eq!(vals(syn::parse_quote!(-> Option<u8>)), ["None", "Some(0)", "Some(1)"]);
        assert_eq!(vals(syn::parse_quote!(-> Result<bool, ()>)), ["Ok(true)", "Ok(false)"]);
        assert_eq!(vals(syn::parse_quote!(-> (u8, bool))), ["(0, true)", "(0, false)", "(1, true)", "(1, false)"]);
        assert_eq!(vals(syn::parse_quote!(-> [u16; 3])), ["[0; 3]", "[1; 3]"]);
        assert_eq!(vals(syn::parse_quote!(-> &'static str)), ["\"\"", "\"xyzzy\""]);
        assert_eq!(vals(syn::parse_quote!(-> Settings)), ["Default::default()"]);
        assert_eq!(
            vals(syn::parse_quote!(-> Option<Frame>)),
            ["None", "unknown Some(Default::default()): a type without a Default"]
        );
        assert!(vals(syn::parse_quote!(-> Frame))[0].starts_with("unknown"));
        assert_eq!(vals(syn::parse_quote!(-> ())), ["unit"]);
        assert!(vals(syn::parse_quote!(-> !)).is_empty());
    }
}
