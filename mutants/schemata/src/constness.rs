//! Which `const fn`s must stay `const` in the copy: those a constant, a static, an array
//! length, an enum discriminant, a `const` block or an item macro calls, and what those
//! call in turn. By name, over every type: a method `byte` kept for one type is kept
//! for all (safe: a kept `const fn` is only a mutant skipped).

use crate::tree::CrateTree;
use proc_macro2::{TokenStream, TokenTree};
use std::collections::BTreeSet;
use syn::visit::{self, Visit};

/// The names of the `const fn`s to keep `const`.
pub(crate) fn needed_const(tree: &CrateTree) -> BTreeSet<String> {
    let mut bodies = ConstFns::default();
    let mut roots = ConstContexts::default();
    for f in &tree.files {
        bodies.visit_file(&f.ast);
        roots.visit_file(&f.ast);
    }
    let mut needed: BTreeSet<String> = roots.calls;
    loop {
        let mut grown = needed.clone();
        for (name, calls) in &bodies.fns {
            if needed.contains(name) {
                grown.extend(calls.iter().cloned());
            }
        }
        if grown == needed {
            break;
        }
        needed = grown;
    }
    let all: BTreeSet<String> = bodies.fns.iter().map(|(n, _)| n.clone()).collect();
    needed.intersection(&all).cloned().collect()
}

/// The names every expression under a node calls (functions and methods).
#[derive(Default)]
struct Calls {
    names: BTreeSet<String>,
}

impl<'ast> Visit<'ast> for Calls {
    fn visit_expr_call(&mut self, e: &'ast syn::ExprCall) {
        if let syn::Expr::Path(p) = &*e.func {
            if let Some(last) = p.path.segments.last() {
                self.names.insert(last.ident.to_string());
            }
        }
        visit::visit_expr_call(self, e);
    }
    fn visit_expr_method_call(&mut self, e: &'ast syn::ExprMethodCall) {
        self.names.insert(e.method.to_string());
        visit::visit_expr_method_call(self, e);
    }
    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        idents(&m.tokens, &mut self.names);
    }
}

fn idents(tokens: &TokenStream, out: &mut BTreeSet<String>) {
    for t in tokens.clone() {
        match t {
            TokenTree::Ident(i) => {
                out.insert(i.to_string());
            }
            TokenTree::Group(g) => idents(&g.stream(), out),
            _ => {}
        }
    }
}

fn calls_in(f: impl FnOnce(&mut Calls)) -> BTreeSet<String> {
    let mut c = Calls::default();
    f(&mut c);
    c.names
}

/// Every `const fn` with the names its body calls.
#[derive(Default)]
struct ConstFns {
    fns: Vec<(String, BTreeSet<String>)>,
}

impl<'ast> Visit<'ast> for ConstFns {
    fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
        if f.sig.constness.is_some() {
            self.fns.push((f.sig.ident.to_string(), calls_in(|c| c.visit_block(&f.block))));
        }
        visit::visit_item_fn(self, f);
    }
    fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
        if f.sig.constness.is_some() {
            self.fns.push((f.sig.ident.to_string(), calls_in(|c| c.visit_block(&f.block))));
        }
        visit::visit_impl_item_fn(self, f);
    }
}

/// The names called where only constants may be computed.
#[derive(Default)]
struct ConstContexts {
    calls: BTreeSet<String>,
}

impl ConstContexts {
    fn take(&mut self, e: &syn::Expr) {
        self.calls.extend(calls_in(|c| c.visit_expr(e)));
    }
}

impl<'ast> Visit<'ast> for ConstContexts {
    fn visit_item_const(&mut self, i: &'ast syn::ItemConst) {
        self.take(&i.expr);
    }
    fn visit_impl_item_const(&mut self, i: &'ast syn::ImplItemConst) {
        self.take(&i.expr);
    }
    fn visit_item_static(&mut self, i: &'ast syn::ItemStatic) {
        self.take(&i.expr);
    }
    fn visit_variant(&mut self, v: &'ast syn::Variant) {
        if let Some((_, e)) = &v.discriminant {
            self.take(e);
        }
    }
    fn visit_type_array(&mut self, t: &'ast syn::TypeArray) {
        self.take(&t.len);
        visit::visit_type_array(self, t);
    }
    fn visit_expr_repeat(&mut self, e: &'ast syn::ExprRepeat) {
        self.take(&e.len);
        visit::visit_expr_repeat(self, e);
    }
    fn visit_expr_const(&mut self, e: &'ast syn::ExprConst) {
        self.calls.extend(calls_in(|c| c.visit_block(&e.block)));
    }
    fn visit_generic_argument(&mut self, a: &'ast syn::GenericArgument) {
        if let syn::GenericArgument::Const(e) = a {
            self.take(e);
        }
        visit::visit_generic_argument(self, a);
    }
    fn visit_item_macro(&mut self, m: &'ast syn::ItemMacro) {
        idents(&m.mac.tokens, &mut self.calls);
    }
}
