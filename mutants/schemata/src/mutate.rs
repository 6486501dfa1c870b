//! The mutants of one file, each compiled in behind its switch (see the crate's
//! documentation for the forms).
//!
//! Long because: the operators' replacement tables and the rewriting that applies them
//! are one pass over a file; under 440 lines without its tests.

use crate::names::{compact, impl_owner, type_name};
use crate::values::{values, Values};
use crate::{Family, Genre, Mutant, Place, Skipped};
use proc_macro2::Span;
use quote::{quote, ToTokens};
use std::collections::BTreeSet;
use syn::spanned::Spanned;
use syn::visit_mut::{self, VisitMut};
use syn::{BinOp, Expr, UnOp};

/// cargo-mutants' replacements of each binary operator, in its order.
fn replacements(op: &str) -> &'static [&'static str] {
    match op {
        "==" => &["!="],
        "!=" => &["=="],
        "<" => &["==", ">", "<="],
        ">" => &["==", "<", ">="],
        "<=" => &[">"],
        ">=" => &["<"],
        "&&" => &["||"],
        "||" => &["&&"],
        "+" => &["-", "*"],
        "-" => &["+", "/"],
        "*" => &["+", "/"],
        "/" => &["%", "*"],
        "%" => &["/", "+"],
        "<<" => &[">>"],
        ">>" => &["<<"],
        "&" => &["|", "^"],
        "|" => &["&", "^"],
        "^" => &["|", "&"],
        "+=" => &["-=", "*="],
        "-=" => &["+=", "/="],
        "*=" => &["+=", "/="],
        "/=" => &["%=", "*="],
        "%=" => &["/=", "+="],
        "<<=" => &[">>="],
        ">>=" => &["<<="],
        "&=" => &["|="],
        "|=" => &["&="],
        "^=" => &["|=", "&="],
        _ => &[],
    }
}

pub(crate) struct Mutator<'a> {
    file: String,
    family: Family,
    defaults: &'a BTreeSet<String>,
    keep_const: &'a BTreeSet<String>,
    not_mutated: &'a dyn Fn(&str) -> bool,
    next_id: &'a mut u32,
    mutants: Vec<Mutant>,
    skipped: Vec<Skipped>,
    /// The impl blocks we are in: the owner's name and its type.
    owners: Vec<(String, syn::Type)>,
    /// The functions we are in, as cargo-mutants names them.
    functions: Vec<String>,
    /// Why mutants here are not switched in (a constant is computed here, or the
    /// function is left out), innermost last.
    frozen: Vec<&'static str>,
}

impl<'a> Mutator<'a> {
    pub(crate) fn new(
        file: String,
        family: Family,
        defaults: &'a BTreeSet<String>,
        keep_const: &'a BTreeSet<String>,
        not_mutated: &'a dyn Fn(&str) -> bool,
        next_id: &'a mut u32,
    ) -> Mutator<'a> {
        Mutator {
            file,
            family,
            defaults,
            keep_const,
            not_mutated,
            next_id,
            mutants: Vec::new(),
            skipped: Vec::new(),
            owners: Vec::new(),
            functions: Vec::new(),
            frozen: Vec::new(),
        }
    }

    pub(crate) fn run(&mut self, file: &mut syn::File) {
        self.visit_file_mut(file);
    }

    pub(crate) fn finish(self) -> (Vec<Mutant>, Vec<Skipped>) {
        (self.mutants, self.skipped)
    }

    fn place(&self, span: Span) -> Place {
        let start = span.start();
        Place { file: self.file.clone(), line: start.line, column: start.column + 1 }
    }

    /// A mutant here: its switch, or `None` where it is recorded as skipped.
    fn register(&mut self, genre: Genre, span: Span, description: String) -> Option<u32> {
        let place = self.place(span);
        if let Some(why) = self.frozen.last() {
            self.skipped.push(Skipped { place, genre, description, why });
            return None;
        }
        // Mutants outside functions (none in cargo-mutants) are not made.
        self.functions.last()?;
        let id = *self.next_id;
        *self.next_id += 1;
        let function = self.functions.last().cloned().unwrap_or_default();
        self.mutants.push(Mutant { id, family: self.family, genre, place, function, description, occurrence: 0 });
        Some(id)
    }

    /// ` in f` for a mutant in function `f`; nothing outside functions (as cargo-mutants).
    fn in_fn(&self) -> String {
        self.functions.last().map(|f| format!(" in {f}")).unwrap_or_default()
    }

    fn frozen_while(&mut self, why: &'static str, f: impl FnOnce(&mut Self)) {
        self.frozen.push(why);
        f(self);
        self.frozen.pop();
    }

    fn qualified(&self, ident: &syn::Ident) -> String {
        match self.owners.last() {
            Some((owner, _)) => format!("{owner}::{ident}"),
            None => ident.to_string(),
        }
    }

    /// A function: its body's mutants, then its values.
    fn function(&mut self, attrs: &[syn::Attribute], sig: &mut syn::Signature, block: &mut syn::Block) {
        if attrs.iter().any(|a| a.path().segments.last().is_some_and(|s| s.ident == "test")) {
            return;
        }
        let name = self.qualified(&sig.ident);
        let keep_const = sig.constness.is_some() && self.keep_const.contains(&sig.ident.to_string());
        if sig.constness.is_some() && !keep_const {
            sig.constness = None;
        }
        let mut why = None;
        if keep_const {
            why = Some("in a `const fn` that a constant needs");
        }
        if (self.not_mutated)(&name) {
            why = Some("a function left out of the scope");
        }
        // cargo-mutants leaves unsafe functions and constructors called `new` alone.
        if sig.unsafety.is_some() || (sig.ident == "new" && !self.owners.is_empty()) {
            return;
        }
        self.functions.push(name.clone());
        if let Some(w) = why {
            self.frozen.push(w);
        }
        let mut guards = self.values(&name, sig, block);
        visit_mut::visit_block_mut(self, block);
        if !guards.is_empty() {
            guards.append(&mut block.stmts);
            block.stmts = guards;
        }
        if why.is_some() {
            self.frozen.pop();
        }
        self.functions.pop();
    }

    /// The function's body replaced by each value of its return type: the switches to
    /// put before the body (once the body's own mutants are in).
    fn values(&mut self, name: &str, sig: &syn::Signature, block: &syn::Block) -> Vec<syn::Stmt> {
        let Some(first) = block.stmts.first() else { return Vec::new() };
        let span = first.span();
        let self_ty = self.owners.last().map(|(_, t)| t.clone());
        // cargo-mutants leaves `Default::default` bodies (its own value for them).
        if sig.ident == "default" && self.owners.last().is_some_and(|(o, _)| o.starts_with("<impl Default for")) {
            return Vec::new();
        }
        let body = match block.stmts.as_slice() {
            [syn::Stmt::Expr(e, None)] => Some(e.to_token_stream().to_string()),
            _ => None,
        };
        let ret = match &sig.output {
            syn::ReturnType::Default => String::new(),
            syn::ReturnType::Type(_, t) => format!(" -> {}", type_name(t)),
        };
        let mut guards: Vec<syn::Stmt> = Vec::new();
        match values(&sig.output, self_ty.as_ref(), self.defaults) {
            Values::None => {}
            Values::Unit => {
                if let Some(id) = self.register(Genre::FnValue, span, format!("replace {name} with ()")) {
                    let lit = switch_id(id);
                    guards.push(syn::parse_quote!(if crate::mutant::on(#lit) { return; }));
                }
            }
            Values::Some(candidates) => {
                for c in candidates {
                    let description = format!("replace {name}{ret} with {}", c.text);
                    match c.code {
                        Ok(v) if body.as_deref() == Some(v.to_string().as_str()) => {}
                        Ok(v) => {
                            if let Some(id) = self.register(Genre::FnValue, span, description) {
                                let lit = switch_id(id);
                                guards.push(syn::parse_quote!(if crate::mutant::on(#lit) { return #v; }));
                            }
                        }
                        Err(why) => {
                            let place = self.place(span);
                            self.skipped.push(Skipped { place, genre: Genre::FnValue, description, why });
                        }
                    }
                }
            }
        }
        guards
    }

    fn binary(&mut self, e: &mut Expr) {
        let Expr::Binary(b) = e else { return };
        let op = compact(&b.op);
        let span = b.op.span();
        let f = self.in_fn();
        let mut arms: Vec<(u32, Expr)> = Vec::new();
        for alt in replacements(&op) {
            let description = format!("replace {op} with {alt}{f}");
            if let Some(id) = self.register(Genre::BinaryOperator, span, description) {
                let Ok(new_op) = syn::parse_str::<BinOp>(alt) else { continue };
                let mut m = b.clone();
                m.op = new_op;
                arms.push((id, Expr::Binary(m)));
            }
        }
        switch(e, arms);
    }

    fn unary(&mut self, e: &mut Expr) {
        let Expr::Unary(u) = e else { return };
        let op = match u.op {
            UnOp::Not(_) => "!",
            UnOp::Neg(_) => "-",
            _ => return,
        };
        let span = u.op.span();
        let description = format!("delete {op}{}", self.in_fn());
        if let Some(id) = self.register(Genre::UnaryOperator, span, description) {
            let inner = (*u.expr).clone();
            switch(e, vec![(id, inner)]);
        }
    }

    fn match_arms(&mut self, m: &mut syn::ExprMatch, before: Vec<ArmText>) {
        let wildcard = m.arms.iter().any(|a| matches!(a.pat, syn::Pat::Wild(_)) && a.guard.is_none());
        let f = self.in_fn();
        for (arm, before) in m.arms.iter_mut().zip(before) {
            if let (Some((_, guard)), Some((text, span))) = (arm.guard.as_mut(), before.guard) {
                let t = self.register(Genre::MatchArmGuard, span, format!("replace match guard {text} with true{f}"));
                let fl = self.register(Genre::MatchArmGuard, span, format!("replace match guard {text} with false{f}"));
                let mut arms = Vec::new();
                if let Some(t) = t {
                    arms.push((t, syn::parse_quote!(true)));
                }
                if let Some(fl) = fl {
                    arms.push((fl, syn::parse_quote!(false)));
                }
                switch(guard, arms);
            } else if wildcard && arm.guard.is_none() && !matches!(arm.pat, syn::Pat::Wild(_)) {
                let (text, span) = before.pattern;
                if let Some(id) = self.register(Genre::MatchArm, span, format!("delete match arm {text}{f}")) {
                    let lit = switch_id(id);
                    let off: Expr = syn::parse_quote!(!crate::mutant::on(#lit));
                    arm.guard = Some((Default::default(), Box::new(off)));
                }
            }
        }
    }
}

impl Mutator<'_> {
    /// A field of a struct expression with a base, deleted: it takes the base's value.
    fn struct_fields(&mut self, s: &mut syn::ExprStruct) {
        let Some(base) = s.rest.as_deref() else { return };
        let base = base.clone();
        let name = compact(&s.path);
        let f = self.in_fn();
        let readable_twice = matches!(base, Expr::Path(_));
        for field in s.fields.iter_mut() {
            let syn::Member::Named(ident) = &field.member else { continue };
            let description = format!("delete field {ident} from struct {name} expression{f}");
            let span = field.member.span();
            if !readable_twice {
                let place = self.place(span);
                let why = "a base that is not a path (it would be evaluated twice)";
                self.skipped.push(Skipped { place, genre: Genre::StructField, description, why });
                continue;
            }
            if let Some(id) = self.register(Genre::StructField, span, description) {
                let ident = ident.clone();
                field.colon_token.get_or_insert_with(Default::default);
                switch(&mut field.expr, vec![(id, syn::parse_quote!(#base.#ident))]);
            }
        }
    }
}

/// A match arm's pattern and guard as written, with where they start.
struct ArmText {
    pattern: (String, Span),
    guard: Option<(String, Span)>,
}

/// A switch's id as written in the copy: `7`, not `7u32`.
fn switch_id(id: u32) -> proc_macro2::Literal {
    proc_macro2::Literal::u32_unsuffixed(id)
}

/// `e` becomes `(if on(a) { x } else if on(b) { y } else { e })`.
fn switch(e: &mut Expr, arms: Vec<(u32, Expr)>) {
    if arms.is_empty() {
        return;
    }
    let mut chain: Expr = e.clone();
    for (id, alt) in arms.into_iter().rev() {
        let lit = switch_id(id);
        chain = syn::parse_quote!(if crate::mutant::on(#lit) { #alt } else { #chain });
    }
    *e = syn::parse2(quote!((#chain))).unwrap_or(chain);
}

impl VisitMut for Mutator<'_> {
    fn visit_item_impl_mut(&mut self, i: &mut syn::ItemImpl) {
        self.owners.push((impl_owner(i), (*i.self_ty).clone()));
        visit_mut::visit_item_impl_mut(self, i);
        self.owners.pop();
    }

    fn visit_item_trait_mut(&mut self, i: &mut syn::ItemTrait) {
        let ty: syn::Type = syn::parse_quote!(Self);
        self.owners.push((i.ident.to_string(), ty));
        visit_mut::visit_item_trait_mut(self, i);
        self.owners.pop();
    }

    fn visit_item_fn_mut(&mut self, f: &mut syn::ItemFn) {
        // A free function nested in an impl's method is not the impl's.
        let owners = std::mem::take(&mut self.owners);
        self.function(&f.attrs, &mut f.sig, &mut f.block);
        self.owners = owners;
    }

    fn visit_impl_item_fn_mut(&mut self, f: &mut syn::ImplItemFn) {
        self.function(&f.attrs, &mut f.sig, &mut f.block);
    }

    fn visit_trait_item_fn_mut(&mut self, f: &mut syn::TraitItemFn) {
        if let Some(block) = f.default.as_mut() {
            self.function(&f.attrs, &mut f.sig, block);
        }
    }

    fn visit_item_const_mut(&mut self, i: &mut syn::ItemConst) {
        self.frozen_while("in a constant", |s| visit_mut::visit_item_const_mut(s, i));
    }

    fn visit_impl_item_const_mut(&mut self, i: &mut syn::ImplItemConst) {
        self.frozen_while("in a constant", |s| visit_mut::visit_impl_item_const_mut(s, i));
    }

    fn visit_item_static_mut(&mut self, i: &mut syn::ItemStatic) {
        self.frozen_while("in a static", |s| visit_mut::visit_item_static_mut(s, i));
    }

    fn visit_variant_mut(&mut self, v: &mut syn::Variant) {
        self.frozen_while("in an enum discriminant", |s| visit_mut::visit_variant_mut(s, v));
    }

    fn visit_type_array_mut(&mut self, t: &mut syn::TypeArray) {
        self.frozen_while("in an array length", |s| visit_mut::visit_type_array_mut(s, t));
    }

    fn visit_expr_repeat_mut(&mut self, e: &mut syn::ExprRepeat) {
        self.visit_expr_mut(&mut e.expr);
        self.frozen_while("in an array length", |s| s.visit_expr_mut(&mut e.len));
    }

    fn visit_expr_const_mut(&mut self, e: &mut syn::ExprConst) {
        self.frozen_while("in a const block", |s| visit_mut::visit_expr_const_mut(s, e));
    }

    fn visit_generic_argument_mut(&mut self, a: &mut syn::GenericArgument) {
        self.frozen_while("in a const generic argument", |s| visit_mut::visit_generic_argument_mut(s, a));
    }

    fn visit_pat_mut(&mut self, _: &mut syn::Pat) {
        // Nothing in a pattern is mutated (cargo-mutants neither): a switch is no pattern.
    }

    fn visit_expr_mut(&mut self, e: &mut Expr) {
        // A match's arms as written, before their own mutants are switched in.
        let arms = match e {
            Expr::Match(m) => m
                .arms
                .iter()
                .map(|a| ArmText {
                    pattern: (compact(&a.pat), a.pat.span()),
                    guard: a.guard.as_ref().map(|(_, g)| (compact(&**g), g.span())),
                })
                .collect(),
            _ => Vec::new(),
        };
        visit_mut::visit_expr_mut(self, e);
        match e {
            Expr::Binary(_) => self.binary(e),
            Expr::Unary(_) => self.unary(e),
            Expr::Match(m) => self.match_arms(m, arms),
            Expr::Struct(st) => self.struct_fields(st),
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mutate(src: &str) -> (String, Vec<Mutant>, Vec<Skipped>) {
        let mut file = syn::parse_file(src).unwrap();
        let defaults = BTreeSet::new();
        let keep: BTreeSet<String> = ["kept".to_string()].into();
        let mut next = 1;
        let none = |_: &str| false;
        let mut m = Mutator::new("f.rs".into(), Family::Encoder, &defaults, &keep, &none, &mut next);
        m.run(&mut file);
        let (ms, sk) = m.finish();
        (prettyplease::unparse(&file), ms, sk)
    }

    #[test]
    fn an_operator_becomes_a_switch_with_cargo_mutants_name_and_place() {
        let (code, ms, _) = mutate("fn f(a: u8, b: u8) -> bool {\n    a == b\n}\n");
        let names: Vec<String> = ms.iter().map(Mutant::name).collect();
        assert_eq!(
            names,
            [
                "f.rs:2:5: replace f -> bool with true",
                "f.rs:2:5: replace f -> bool with false",
                "f.rs:2:7: replace == with != in f"
            ]
        );
        assert!(code.contains("if crate::mutant::on(3) { a != b } else { a == b }"), "{code}");
        assert!(code.contains("if crate::mutant::on(1) {\n        return true;"), "{code}");
    }

    #[test]
    fn a_const_fn_a_constant_needs_keeps_its_mutants_out() {
        let (code, ms, sk) = mutate("const fn kept(a: u8) -> u8 { a + 1 }\nconst fn freed(a: u8) -> u8 { a + 1 }\n");
        assert!(code.contains("const fn kept"), "{code}");
        assert!(!code.contains("const fn freed"), "{code}");
        assert!(ms.iter().all(|m| m.function == "freed"));
        assert_eq!(sk.len(), 4, "{sk:?}");
    }

    #[test]
    fn match_arms_are_deleted_only_before_a_wildcard() {
        let (code, ms, _) =
            mutate("fn f(a: u8, p: bool) -> u8 {\n    match a { 0 => 1, 1 if p => 2, _ => 3 }\n}\nfn g(a: bool) -> u8 { match a { true => 1, false => 2 } }\n");
        let mut d: Vec<&str> = ms.iter().map(|m| m.description.as_str()).filter(|d| d.contains("match")).collect();
        d.sort();
        assert_eq!(
            d,
            [
                "delete match arm 0 in f",
                "replace match guard p with false in f",
                "replace match guard p with true in f"
            ]
        );
        assert!(code.contains("0 if !crate::mutant::on("), "{code}");
    }
}
