//! Parsing `model!` input: one or more `struct Name { kind: planar, links: 3 }` items.
//!
//! Mistakes in the fields are collected and reported together, each pointing at the
//! user's token; only a malformed item (no `struct`, no braces, a missing `:` or `,`)
//! stops parsing at once.

use std::collections::BTreeSet;

use proc_macro2::{Span, TokenStream, TokenTree};
use syn::ext::IdentExt;
use syn::parse::{Parse, ParseStream};
use syn::{Attribute, Generics, Ident, Lit, Token, Visibility, braced};

use crate::plan::{Algorithm, Kind};

/// The most links a generated model may have.
pub const MAX_LINKS: usize = 16;

/// The whole macro input.
pub struct Input {
    /// The struct items, in input order.
    pub models: Vec<ModelDef>,
}

/// One struct item: `#[attrs] vis struct Name { kind: K, links: N }`.
pub struct ModelDef {
    /// Outer attributes and doc comments, passed through to the struct.
    pub attrs: Vec<Attribute>,
    /// The struct's visibility, also given to its constructor.
    pub vis: Visibility,
    /// The struct's name.
    pub ident: Ident,
    /// Planar or spatial.
    pub kind: Kind,
    /// Number of links, `1..=MAX_LINKS`.
    pub links: usize,
    /// The algorithm asked for with `algorithm: dense | tension`, if any.
    pub algorithm: Option<Algorithm>,
}

/// Collects errors so that several mistakes are reported at once (serde's `Ctxt`).
#[derive(Default)]
struct Errors(Option<syn::Error>);

impl Errors {
    fn push(&mut self, error: syn::Error) {
        match &mut self.0 {
            Some(all) => all.combine(error),
            None => self.0 = Some(error),
        }
    }

    fn finish(self) -> syn::Result<()> {
        self.0.map_or(Ok(()), Err)
    }
}

impl Parse for Input {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        if input.is_empty() {
            return Err(syn::Error::new(
                Span::call_site(),
                "`model!` expects at least one `struct Name { kind: planar, links: 3 }`",
            ));
        }
        let mut errors = Errors::default();
        let mut models = Vec::new();
        while !input.is_empty() {
            if let Some(model) = ModelDef::parse(input, &mut errors)? {
                models.push(model);
            }
        }
        let mut seen = BTreeSet::new();
        for model in &models {
            if !seen.insert(model.ident.to_string()) {
                errors.push(syn::Error::new_spanned(
                    &model.ident,
                    format!("duplicate struct `{}` in this `model!`", model.ident),
                ));
            }
        }
        errors.finish()?;
        Ok(Input { models })
    }
}

/// A field's value: the tokens up to the next top-level `,`.
struct Field {
    name: Ident,
    colon: Token![:],
    value: TokenStream,
}

impl ModelDef {
    /// Parses one item; `Ok(None)` when its fields had mistakes (pushed to `errors`).
    fn parse(input: ParseStream, errors: &mut Errors) -> syn::Result<Option<Self>> {
        let attrs = input.call(Attribute::parse_outer)?;
        let vis: Visibility = input.parse()?;
        input.parse::<Token![struct]>()?;
        let ident: Ident = input.parse()?;
        if input.peek(Token![<]) {
            let generics: Generics = input.parse()?;
            errors.push(syn::Error::new_spanned(
                &generics,
                format!("`{ident}` cannot have generic parameters: a generated model is a plain struct"),
            ));
        }
        let content;
        braced!(content in input);
        let mut kind = None;
        let mut links = None;
        let mut algorithm = None;
        let mut seen = BTreeSet::new();
        let mut ok = true;
        while !content.is_empty() {
            let field = Field::parse(&content)?;
            let name = field.name.to_string();
            let result = match name.as_str() {
                "kind" | "links" | "algorithm" if seen.contains(&name) => {
                    Err(syn::Error::new_spanned(&field.name, format!("duplicate field `{name}`")))
                }
                "kind" => field.kind().map(|k| kind = Some(k)),
                "links" => field.links().map(|n| links = Some(n)),
                "algorithm" => field.algorithm().map(|a| algorithm = Some(a)),
                other => Err(syn::Error::new_spanned(
                    &field.name,
                    format!("unknown field `{other}`, expected `kind`, `links` or `algorithm`"),
                )),
            };
            seen.insert(name);
            if let Err(e) = result {
                errors.push(e);
                ok = false;
            }
            if content.is_empty() {
                break;
            }
            content.parse::<Token![,]>()?;
        }
        if !seen.contains("kind") {
            errors.push(syn::Error::new_spanned(
                &ident,
                format!("missing field `kind` in `{ident}`, expected `kind: planar` or `kind: spatial`"),
            ));
        }
        if !seen.contains("links") {
            errors.push(syn::Error::new_spanned(
                &ident,
                format!(
                    "missing field `links` in `{ident}`, expected `links: N` with N from 1 to {MAX_LINKS}"
                ),
            ));
        }
        Ok(match (kind, links) {
            (Some(kind), Some(links)) if ok => Some(ModelDef { attrs, vis, ident, kind, links, algorithm }),
            _ => None,
        })
    }
}

/// The tokens as the user would write them (`-3`, not `- 3`).
fn render(tokens: &TokenStream) -> String {
    let text = tokens.to_string();
    text.strip_prefix("- ").map_or(text.clone(), |rest| format!("-{rest}"))
}

impl Field {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        // `Ident::parse_any` so that a keyword (`type: planar`) is an unknown field, not a
        // parse error.
        let name = input.call(Ident::parse_any)?;
        let colon: Token![:] = input.parse()?;
        let mut value = TokenStream::new();
        while !input.is_empty() && !input.peek(Token![,]) {
            if !value.is_empty() && input.peek(Ident::peek_any) && input.peek2(Token![:]) {
                return Err(input.error(format!("expected `,` after the value of `{name}`")));
            }
            value.extend([input.parse::<TokenTree>()?]);
        }
        Ok(Field { name, colon, value })
    }

    /// The single token of the value, or an error naming what was expected.
    fn single(&self, expected: &str) -> syn::Result<TokenTree> {
        let mut tokens = self.value.clone().into_iter();
        match (tokens.next(), tokens.next()) {
            (Some(token), None) => Ok(token),
            (None, _) => Err(syn::Error::new_spanned(
                self.colon,
                format!("missing value for `{}`, expected {expected}", self.name),
            )),
            (Some(_), Some(_)) => Err(syn::Error::new_spanned(
                &self.value,
                format!("`{}` must be {expected}, got `{}`", self.name, render(&self.value)),
            )),
        }
    }

    fn kind(&self) -> syn::Result<Kind> {
        const EXPECTED: &str = "`planar` or `spatial`";
        match self.single(EXPECTED)? {
            TokenTree::Ident(ident) if ident == "planar" => Ok(Kind::Planar),
            TokenTree::Ident(ident) if ident == "spatial" => Ok(Kind::Spatial),
            TokenTree::Ident(ident) => {
                Err(syn::Error::new_spanned(&ident, format!("unknown kind `{ident}`, expected {EXPECTED}")))
            }
            other => {
                Err(syn::Error::new_spanned(&other, format!("`kind` must be {EXPECTED}, got `{other}`")))
            }
        }
    }

    fn algorithm(&self) -> syn::Result<Algorithm> {
        const EXPECTED: &str = "`dense` (mass matrix and L D Lᵀ) or `tension` (the O(n) rod-tension solve)";
        match self.single(EXPECTED)? {
            TokenTree::Ident(ident) if ident == "dense" => Ok(Algorithm::Dense),
            TokenTree::Ident(ident) if ident == "tension" => Ok(Algorithm::Tension),
            TokenTree::Ident(ident) => Err(syn::Error::new_spanned(
                &ident,
                format!("unknown algorithm `{ident}`, expected {EXPECTED}"),
            )),
            other => Err(syn::Error::new_spanned(
                &other,
                format!("`algorithm` must be {EXPECTED}, got `{}`", render(&other.clone().into())),
            )),
        }
    }

    fn links(&self) -> syn::Result<usize> {
        let expected = format!("an integer literal from 1 to {MAX_LINKS}");
        let token = self.single(&expected)?;
        let Ok(Lit::Int(lit)) = syn::parse2::<Lit>(token.clone().into()) else {
            return Err(syn::Error::new_spanned(
                &token,
                format!("`links` must be {expected}, got `{token}`"),
            ));
        };
        match lit.base10_parse::<usize>() {
            Ok(n) if (1..=MAX_LINKS).contains(&n) => Ok(n),
            _ => Err(syn::Error::new_spanned(
                &lit,
                format!("`links` must be between 1 and {MAX_LINKS}, got {}", lit.base10_digits()),
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(src: &str) -> syn::Result<Input> {
        syn::parse_str::<Input>(src)
    }

    fn messages(src: &str) -> Vec<String> {
        match parse(src) {
            Ok(_) => Vec::new(),
            Err(e) => e.into_iter().map(|e| e.to_string()).collect(),
        }
    }

    #[test]
    fn parses_several_items_with_attributes_and_visibility() {
        let input = parse(
            "/// Doc.\n#[allow(dead_code)] pub struct P3 { kind: planar, links: 3 }
             pub(crate) struct S2 { links: 2, kind: spatial, }",
        )
        .unwrap();
        let [p, s] = &input.models[..] else { panic!("two items") };
        assert_eq!((p.ident.to_string(), p.kind, p.links, p.attrs.len()), ("P3".into(), Kind::Planar, 3, 2));
        assert_eq!((s.ident.to_string(), s.kind, s.links), ("S2".into(), Kind::Spatial, 2));
        assert!(matches!(s.vis, Visibility::Restricted(_)));
    }

    #[test]
    fn collects_every_mistake() {
        let got = messages(
            "struct A { kind: circular, links: 40, mass: 1 }
             struct B { kind: planar, kind: spatial, links: 2.5 }
             struct C { kind: planar }",
        );
        assert_eq!(
            got,
            [
                "unknown kind `circular`, expected `planar` or `spatial`",
                "`links` must be between 1 and 16, got 40",
                "unknown field `mass`, expected `kind`, `links` or `algorithm`",
                "duplicate field `kind`",
                "`links` must be an integer literal from 1 to 16, got `2.5`",
                "missing field `links` in `C`, expected `links: N` with N from 1 to 16",
            ]
        );
    }

    #[test]
    fn odd_values_are_named() {
        assert_eq!(
            messages("struct A { kind: planar, links: 0 }"),
            ["`links` must be between 1 and 16, got 0"]
        );
        assert_eq!(
            messages("struct A { kind: planar, links: -1 }"),
            ["`links` must be an integer literal from 1 to 16, got `-1`"]
        );
        assert_eq!(
            messages("struct A { kind: \"planar\", links: 1 }"),
            ["`kind` must be `planar` or `spatial`, got `\"planar\"`"]
        );
        assert_eq!(
            messages("struct A { kind:, links: 1 }"),
            ["missing value for `kind`, expected `planar` or `spatial`"]
        );
        assert_eq!(
            messages("struct A { kind: planar, links: 99999999999999999999999 }"),
            ["`links` must be between 1 and 16, got 99999999999999999999999"]
        );
        assert_eq!(
            messages("struct A { type: planar, links: 1 }"),
            [
                "unknown field `type`, expected `kind`, `links` or `algorithm`",
                "missing field `kind` in `A`, expected `kind: planar` or `kind: spatial`"
            ]
        );
        assert_eq!(
            messages("struct A<T> { kind: planar, links: 1 }"),
            ["`A` cannot have generic parameters: a generated model is a plain struct"]
        );
        assert_eq!(
            messages("struct A { kind: planar, links: 1 } struct A { kind: spatial, links: 1 }"),
            ["duplicate struct `A` in this `model!`"]
        );
    }

    #[test]
    fn a_missing_comma_stops_at_the_next_field() {
        assert_eq!(
            messages("struct A { kind: planar links: 1 }"),
            ["expected `,` after the value of `kind`"]
        );
        assert_eq!(
            messages("struct A { kind: planar, links: 1 + 2 }"),
            ["`links` must be an integer literal from 1 to 16, got `1 + 2`"]
        );
    }

    #[test]
    fn the_algorithm_is_optional_and_named_when_wrong() {
        let input = parse(
            "struct A { kind: planar, links: 3 } struct B { kind: planar, links: 3, algorithm: tension }
             struct C { algorithm: dense, kind: spatial, links: 2 }",
        )
        .unwrap();
        let algorithms: Vec<_> = input.models.iter().map(|m| m.algorithm).collect();
        assert_eq!(algorithms, [None, Some(Algorithm::Tension), Some(Algorithm::Dense)]);
        const EXPECTED: &str = "`dense` (mass matrix and L D Lᵀ) or `tension` (the O(n) rod-tension solve)";
        assert_eq!(
            messages("struct A { kind: planar, links: 3, algorithm: sparse }"),
            [format!("unknown algorithm `sparse`, expected {EXPECTED}")]
        );
        assert_eq!(
            messages("struct A { kind: planar, links: 3, algorithm: \"tension\" }"),
            [format!("`algorithm` must be {EXPECTED}, got `\"tension\"`")]
        );
        assert_eq!(
            messages("struct A { kind: planar, links: 3, algorithm: dense, algorithm: tension }"),
            ["duplicate field `algorithm`"]
        );
        assert_eq!(
            messages("struct A { kind: planar, links: 3, algorithm: }"),
            [format!("missing value for `algorithm`, expected {EXPECTED}")]
        );
    }

    #[test]
    fn empty_input_says_what_is_expected() {
        assert_eq!(messages(""), ["`model!` expects at least one `struct Name { kind: planar, links: 3 }`"]);
    }
}
