//! Types, patterns and expressions written as cargo-mutants writes them in a mutant's
//! name: `Bytes<N>`, `Hex<'_>`, `-> Option<u8>`, `Response::Data{field, offset, data}`.

use quote::ToTokens;

/// Tokens as one line, with the spaces `TokenStream`'s printing puts around `<`, `>`,
/// `::`, `&`, `'` and before `,` and `(` taken out.
pub(crate) fn compact(tokens: &impl ToTokens) -> String {
    let s = tokens.to_token_stream().to_string();
    let mut out = String::with_capacity(s.len());
    let chars: Vec<char> = s.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c == ' ' {
            let prev = out.chars().last();
            let next = chars.get(i + 1).copied();
            let glue_after = matches!(prev, Some('<' | ':' | '&' | '\'' | '(' | '[' | '!' | '{' | '.' | '@'));
            let rest_after_comma = prev == Some(',') && next == Some('.');
            let glue_before = !rest_after_comma
                && matches!(next, Some('<' | '>' | ':' | ',' | '(' | ')' | ']' | '.' | ';' | '}' | '?'));
            if glue_after || glue_before {
                i += 1;
                continue;
            }
        }
        out.push(c);
        i += 1;
    }
    // `-> T`, `for X` and `=> ` keep their spaces; `Fn {` closes up as cargo-mutants
    // prints struct patterns: `Data{field, offset}`.
    let out = out.replace(" {", "{").replace("{ ", "{");
    // A unary minus: `-1`, `(0, -1)`.
    let out = out.replace("(- ", "(-").replace(", - ", ", -").replace("[- ", "[-");
    match out.strip_prefix("- ") {
        Some(rest) => format!("-{rest}"),
        None => out,
    }
}

/// A type as cargo-mutants writes it.
pub(crate) fn type_name(ty: &syn::Type) -> String {
    let s = compact(ty);
    // A reference's lifetime: `&'static str` keeps the space after the lifetime.
    s.replace("&'static", "&'static ")
        .replace("&'static  ", "&'static ")
        .replace("&'_", "&'_ ")
        .replace("&'_  ", "&'_ ")
}

/// The name of an `impl` block's functions' owner: `Type` for inherent impls,
/// `<impl Trait for Type>` for trait impls.
pub(crate) fn impl_owner(i: &syn::ItemImpl) -> String {
    let ty = type_name(&i.self_ty);
    match &i.trait_ {
        Some((_, path, _)) => format!("<impl {} for {}>", compact(path), ty),
        None => ty,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_as_cargo_mutants_prints_them() {
        let t: syn::Type = syn::parse_quote!(Option<(u8, u16)>);
        assert_eq!(type_name(&t), "Option<(u8, u16)>");
        let t: syn::Type = syn::parse_quote!(&'static str);
        assert_eq!(type_name(&t), "&'static str");
        let t: syn::Type = syn::parse_quote!(Hex<'_>);
        assert_eq!(type_name(&t), "Hex<'_>");
        let t: syn::Type = syn::parse_quote!([u16; 3]);
        assert_eq!(type_name(&t), "[u16; 3]");
        let i: syn::ItemImpl = syn::parse_quote!(impl fmt::Display for Hex<'_> {});
        assert_eq!(impl_owner(&i), "<impl fmt::Display for Hex<'_>>");
        let i: syn::ItemImpl = syn::parse_quote!(
            impl<const N: usize> Bytes<N> {}
        );
        assert_eq!(impl_owner(&i), "Bytes<N>");
        let p: syn::Pat = syn::Pat::parse_single.parse2(quote::quote!(Response::Data { field, offset, data })).unwrap();
        assert_eq!(compact(&p), "Response::Data{field, offset, data}");
        let p: syn::Pat = syn::Pat::parse_single.parse2(quote::quote!((None, Some(new)))).unwrap();
        assert_eq!(compact(&p), "(None, Some(new))");
    }

    use syn::parse::Parser;
}
