//! What a piece of generated code reads, and how much of it there is:
//! the chunks (`chunk`) hand each function the frame locals its steps
//! name, and a rolled run (`roll`) its parameters, by the same count.

use std::collections::HashSet;

use proc_macro2::{TokenStream, TokenTree};
use quote::format_ident;

/// The identifiers of a step's code that matter to its chunk: the frame
/// locals (poses, points, inputs) and the parameters.
#[derive(Default)]
pub(super) struct Uses {
    idents: HashSet<String>,
    /// Number of tokens, groups counted once plus their contents.
    pub weight: usize,
}

impl Uses {
    /// What `tokens` name, and their weight.
    pub fn of(tokens: &TokenStream) -> Uses {
        let mut u = Uses::default();
        u.add(tokens);
        u
    }

    pub fn merge(&mut self, other: Uses) {
        self.idents.extend(other.idents);
        self.weight += other.weight;
    }

    fn add(&mut self, tokens: &TokenStream) {
        for t in tokens.clone() {
            self.weight += 1;
            match t {
                TokenTree::Group(g) => self.add(&g.stream()),
                TokenTree::Ident(i) => {
                    self.idents.insert(i.to_string());
                }
                _ => {}
            }
        }
    }

    /// The identifiers named, in no order.
    pub fn idents(&self) -> impl Iterator<Item = &String> {
        self.idents.iter()
    }

    /// Whether the code names `ident`.
    pub fn has(&self, ident: &str) -> bool {
        self.idents.contains(ident)
    }
}

/// A generated function's parameter `name`, `_`-prefixed when its code
/// does not use it.
pub(super) fn param(name: &str, used: bool) -> proc_macro2::Ident {
    if used {
        format_ident!("{}", name)
    } else {
        format_ident!("_{}", name)
    }
}
