//! What the expansions do with the angles: no loops, each angle's sine and cosine taken
//! once per method, and the polar-angle checks given those sines.

use std::collections::BTreeMap;

use proc_macro2::{Delimiter, TokenStream, TokenTree};
use quote::quote;

use super::expand;
use crate::parse::Input;

fn idents(tokens: TokenStream, out: &mut Vec<String>) {
    for token in tokens {
        match token {
            proc_macro2::TokenTree::Ident(i) => out.push(i.to_string()),
            proc_macro2::TokenTree::Group(g) => idents(g.stream(), out),
            _ => {}
        }
    }
}

/// Every `fn name(…) … { body }` in `tokens`, at any depth, as (name, body).
fn methods(tokens: TokenStream, out: &mut Vec<(String, TokenStream)>) {
    let tokens: Vec<TokenTree> = tokens.into_iter().collect();
    let mut k = 0;
    while k < tokens.len() {
        match &tokens[k] {
            TokenTree::Ident(i) if i == "fn" => {
                let name = tokens[k + 1].to_string();
                let (at, body) = tokens[k..]
                    .iter()
                    .enumerate()
                    .find_map(|(j, t)| match t {
                        TokenTree::Group(g) if g.delimiter() == Delimiter::Brace => Some((k + j, g)),
                        _ => None,
                    })
                    .expect("a fn has a body");
                out.push((name, body.stream()));
                k = at + 1;
            }
            TokenTree::Group(g) => {
                methods(g.stream(), out);
                k += 1;
            }
            _ => k += 1,
        }
    }
}

/// `i` if `tokens` start with `q[i]`.
fn q_index(tokens: &[TokenTree]) -> Option<String> {
    match tokens {
        [TokenTree::Ident(q), TokenTree::Group(g), ..] if q == "q" && g.delimiter() == Delimiter::Bracket => {
            Some(g.stream().to_string())
        }
        _ => None,
    }
}

/// What one method body does with the angles `q[i]`: the trig calls on each (`.sin()`,
/// `.cos()`, `.sin_cos()`, and `check_polar_angle(_, q[i])`, which takes the sine
/// itself), the names bound to each sine, and the `check_polar_sin(_, q[i], s)` calls.
#[derive(Default)]
struct AngleUses {
    trig: Vec<(String, String)>,
    sine: BTreeMap<String, String>,
    checks: Vec<(String, String)>,
}

fn angle_uses(body: TokenStream, uses: &mut AngleUses) {
    let tokens: Vec<TokenTree> = body.into_iter().collect();
    for (k, token) in tokens.iter().enumerate() {
        match token {
            TokenTree::Group(g) => angle_uses(g.stream(), uses),
            TokenTree::Ident(f) if f == "check_polar_angle" || f == "check_polar_sin" => {
                let Some(TokenTree::Group(args)) = tokens.get(k + 1) else { continue };
                let args: Vec<TokenTree> = args.stream().into_iter().collect();
                let args: Vec<&[TokenTree]> =
                    args.split(|t| matches!(t, TokenTree::Punct(p) if p.as_char() == ',')).collect();
                let i = q_index(args[1]).expect("the checks take q[i]");
                if f == "check_polar_angle" {
                    uses.trig.push((i, f.to_string()));
                } else {
                    uses.checks.push((i, args[2].iter().map(ToString::to_string).collect()));
                }
            }
            // `let [s, c] = trig[i]`: the sine and cosine of `q[i]` from the vectorised
            // kernel (`sin_cos_into(q.as_slice(), &mut trig)`).
            TokenTree::Ident(t) if t == "trig" => {
                let Some(TokenTree::Group(at)) = tokens.get(k + 1) else { continue };
                if at.delimiter() != Delimiter::Bracket {
                    continue;
                }
                let i = at.stream().to_string();
                if let Some([TokenTree::Ident(l), TokenTree::Group(pair), TokenTree::Punct(eq)]) =
                    k.checked_sub(3).map(|p| &tokens[p..k])
                    && l == "let"
                    && eq.as_char() == '='
                    && let Some(s) = pair.stream().into_iter().next()
                {
                    uses.sine.insert(s.to_string(), i.clone());
                }
                uses.trig.push((i, "sin_cos_into".into()));
            }
            TokenTree::Ident(_) => {
                let Some(i) = q_index(&tokens[k..]) else { continue };
                let Some(TokenTree::Ident(method)) = tokens.get(k + 3) else { continue };
                let method = method.to_string();
                if !["sin", "cos", "sin_cos"].contains(&method.as_str()) {
                    continue;
                }
                // `let s = q[i].sin()` or `let (s, c) = q[i].sin_cos()`
                let bound = match (k.checked_sub(3).map(|p| &tokens[p..k]), method.as_str()) {
                    (Some([TokenTree::Ident(l), TokenTree::Ident(s), TokenTree::Punct(eq)]), "sin")
                        if l == "let" && eq.as_char() == '=' =>
                    {
                        Some(s.to_string())
                    }
                    (
                        Some([TokenTree::Ident(l), TokenTree::Group(pair), TokenTree::Punct(eq)]),
                        "sin_cos",
                    ) if l == "let" && eq.as_char() == '=' => {
                        pair.stream().into_iter().next().map(|s| s.to_string())
                    }
                    _ => None,
                };
                if let Some(s) = bound {
                    uses.sine.insert(s, i.clone());
                }
                uses.trig.push((i, method));
            }
            _ => {}
        }
    }
}

/// Per method of `tokens`: an angle with more than one trig call, or a
/// `check_polar_sin` given something other than its angle's sine from this method.
fn repeated_trig(tokens: TokenStream) -> Vec<String> {
    let mut found = Vec::new();
    let mut all = Vec::new();
    methods(tokens, &mut all);
    for (name, body) in all {
        let mut uses = AngleUses::default();
        angle_uses(body, &mut uses);
        let mut per_angle: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
        for (i, call) in &uses.trig {
            per_angle.entry(i).or_default().push(call);
        }
        for (i, calls) in per_angle.into_iter().filter(|(_, calls)| calls.len() > 1) {
            found.push(format!("{name}: q[{i}] has {calls:?}"));
        }
        for (i, sine) in &uses.checks {
            if uses.sine.get(sine) != Some(i) {
                found.push(format!("{name}: check_polar_sin of q[{i}] is given `{sine}`"));
            }
        }
    }
    found
}

fn expansion(item: &str) -> TokenStream {
    expand(&syn::parse_str::<Input>(item).unwrap())
}

#[test]
fn expansion_has_no_loops() {
    for item in [
        "struct S3 { kind: spatial, links: 3 }",
        "struct S3 { kind: spatial, links: 3, algorithm: dense }",
        "struct S3 { kind: spatial, links: 3, algorithm: tension }",
        "struct P9 { kind: planar, links: 9, algorithm: tension }",
    ] {
        let mut words = Vec::new();
        idents(expansion(item), &mut words);
        for word in ["in", "while", "loop", "Vec", "vec", "Box", "iter", "collect"] {
            assert!(!words.iter().any(|w| w == word), "{item}: the expansion contains `{word}`");
        }
    }
}

#[test]
fn every_method_takes_each_angles_sine_and_cosine_once() {
    for (kind, algorithm) in
        [("planar", "dense"), ("planar", "tension"), ("spatial", "dense"), ("spatial", "tension")]
    {
        for links in [1, 2, 3, 5] {
            let tokens =
                expansion(&format!("struct S {{ kind: {kind}, links: {links}, algorithm: {algorithm} }}"));
            let found = repeated_trig(tokens.clone());
            assert!(found.is_empty(), "{kind} {links} {algorithm}: {found:#?}");
            // The spatial checks: every link's, in both methods that make them.
            let mut all = Vec::new();
            methods(tokens, &mut all);
            for (name, body) in all {
                let mut uses = AngleUses::default();
                angle_uses(body, &mut uses);
                let checked: Vec<String> = uses.checks.into_iter().map(|(i, _)| i).collect();
                let want: Vec<String> = match (kind, name.as_str()) {
                    ("spatial", "check_configuration" | "accelerations") => {
                        (0..links).map(|i| i.to_string()).collect()
                    }
                    _ => Vec::new(),
                };
                assert_eq!(checked, want, "{kind} {links} {algorithm}: {name}");
            }
        }
    }
}

#[test]
fn repeated_trig_finds_a_second_use_of_an_angle() {
    let bad = [
        // the sine twice: once in the check, once in the let
        quote!(
            fn a(q: V) {
                check_polar_angle(1, q[0])?;
                let (st0, ct0) = q[0].sin_cos();
            }
        ),
        quote!(
            fn b(q: V) {
                let st0 = q[0].sin();
                let (s, c) = q[0].sin_cos();
            }
        ),
        quote!(
            fn c(q: V) {
                let x = 1.0 + q[1].cos() * q[1].cos();
            }
        ),
        // the check given another angle's sine, or a sine from nowhere
        quote!(
            fn d(q: V) {
                let (st0, ct0) = q[0].sin_cos();
                let st1 = q[1].sin();
                check_polar_sin(1, q[0], st1)?;
            }
        ),
        quote!(
            fn e(q: V) {
                check_polar_sin(1, q[0], st0)?;
            }
        ),
        quote!(
            fn f(q: V) {
                let x = st0 * q[0].sin();
                check_polar_sin(1, q[0], st0)?;
            }
        ),
    ];
    for tokens in bad {
        assert_eq!(repeated_trig(tokens.clone()).len(), 1, "{tokens}");
    }
    let good = quote! {
        fn f(q: V) { let (st0, ct0) = q[0].sin_cos(); check_polar_sin(1, q[0], st0)?; let c1 = q[1].cos(); }
        fn g(q: V) { let st0 = q[0].sin(); check_polar_sin(1, q[0], st0)?; let c1 = q[1].cos(); }
    };
    assert_eq!(repeated_trig(good), Vec::<String>::new());
}
