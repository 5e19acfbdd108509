//! The constants of a module's `body` and `marker` modules, written as
//! text exactly as prettyplease lays them out.
//!
//! A 20,000-loop chain has 100,000 of them. Quoting each one, parsing it
//! with `syn` and laying it out with prettyplease was half of `emit`'s
//! time there, and the part that grew faster than the chain (the
//! allocator's work on millions of short-lived tokens). A constant this
//! writer cannot lay out with certainty (a line past prettyplease's
//! margin, a name a string literal would escape) still goes through
//! prettyplease, so the text is the same either way; the tests compare
//! the two around the margin.

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::{index, lit, Sink};

/// prettyplease's line width: a line longer than this is broken.
const MARGIN: usize = 89;

/// One constant of the `body` or `marker` module.
pub(super) struct Constant<'a> {
    /// The name as the file writes it (`coupler.B`), the constant's doc.
    pub name: &'a str,
    /// The constant's Rust name (`COUPLER_B`).
    pub ident: &'a str,
    /// Its value.
    pub value: Value<'a>,
}

/// What a constant holds.
pub(super) enum Value<'a> {
    /// A body's index: `pub const NAME: usize = 3;`.
    Index(usize),
    /// A marker: `pub const NAME: TY = TY::new("body.m", body, [x, y]);`.
    Marker {
        /// The marker type's name (`Marker`, `Marker3`).
        ty: &'a str,
        /// Its body's index.
        body: usize,
        /// Its local coordinates.
        at: &'a [f64],
    },
}

impl Constant<'_> {
    /// The constant as prettyplease lays it out one level inside a module
    /// (indented by four spaces), doc line included, ending in a newline.
    pub fn laid_out(&self) -> String {
        self.by_hand().unwrap_or_else(|| self.by_prettyplease())
    }

    /// The constant's tokens, as the emitter wrote them before this
    /// writer (and still does for the constants it hands to prettyplease).
    fn tokens(&self) -> TokenStream {
        let doc = format!(" `{}`", self.name);
        let c = format_ident!("{}", self.ident);
        match self.value {
            Value::Index(i) => {
                let i = index(i);
                quote! {
                    #[doc = #doc]
                    pub const #c: usize = #i;
                }
            }
            Value::Marker { ty, body, at } => {
                let (ty, name, body) = (format_ident!("{}", ty), self.name, index(body));
                let at = at.iter().map(|&x| lit(x));
                quote! {
                    #[doc = #doc]
                    pub const #c: #ty = #ty::new(#name, #body, [#(#at),*]);
                }
            }
        }
    }

    fn by_prettyplease(&self) -> String {
        let tokens = self.tokens();
        let text = Sink::lay_out(quote!(mod m { #tokens }));
        (text.strip_prefix("mod m {\n").and_then(|t| t.strip_suffix("}\n")))
            .expect("a module of one item")
            .to_string()
    }

    /// The layout written directly, or `None` where it might differ from
    /// prettyplease's.
    fn by_hand(&self) -> Option<String> {
        let name = Literal::string(self.name).to_string();
        // A name a string literal escapes (quotes, backslashes, control
        // characters) is also one a doc comment may be written otherwise.
        if name.len() != self.name.len() + 2 || self.name.contains('\n') {
            return None;
        }
        let mut out = format!("    /// `{}`\n", self.name);
        let head = format!("    pub const {}", self.ident);
        let line = match self.value {
            Value::Index(i) => format!("{head}: usize = {i};"),
            Value::Marker { ty, body, at } => {
                let at: Vec<String> = at.iter().map(|&x| lit(x).to_string()).collect();
                let args = [name, body.to_string(), format!("[{}]", at.join(", "))];
                let line = format!("{head}: {ty} = {ty}::new({});", args.join(", "));
                if line.len() > MARGIN {
                    // Too long for a line: prettyplease puts each argument
                    // on a line of its own, with a trailing comma.
                    let mut lines = vec![format!("{head}: {ty} = {ty}::new(")];
                    lines.extend(args.iter().map(|a| format!("        {a},")));
                    lines.push("    );".to_string());
                    if lines.iter().any(|l| l.len() > MARGIN) {
                        return None;
                    }
                    for l in lines {
                        out.push_str(&l);
                        out.push('\n');
                    }
                    return Some(out);
                }
                line
            }
        };
        if line.len() > MARGIN {
            return None;
        }
        out.push_str(&line);
        out.push('\n');
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn both(c: &Constant) {
        assert_eq!(c.laid_out(), c.by_prettyplease(), "{}", c.name);
    }

    /// Names of every length from 1 to 100 characters, so that lines of
    /// every length around the margin are met, with short and long
    /// coordinates, in both dimensions, and names a literal escapes: the
    /// hand layout equals prettyplease's.
    #[test]
    fn hand_layout_is_prettypleases() {
        let coordinates: [&[f64]; 5] = [
            &[0.0, 0.0],
            &[-1.5, 2.25],
            &[0.6071067811865475, -0.7171067811865461],
            &[8.789374273786006, 0.0, -1.0000000000000002e-7],
            &[1e300, -2.2250738585072014e-308, 0.1],
        ];
        let (mut short, mut short_by_hand) = (0, 0);
        for n in 1..=100 {
            let name: String = (0..n).map(|k| if k % 7 == 3 { '.' } else { 'a' }).collect();
            // Identifiers one longer than the name too: every line length.
            for ident in [
                name.to_uppercase().replace('.', "_"),
                format!("{}Z", name.to_uppercase().replace('.', "_")),
            ] {
                // The last coordinates print 300 digits: prettyplease breaks
                // even the array, which the hand layout leaves to it.
                let mut check = |c: Constant, usual: bool| {
                    both(&c);
                    if n <= 20 && usual {
                        short += 1;
                        short_by_hand += usize::from(c.by_hand().is_some());
                    }
                };
                for (k, at) in coordinates.iter().enumerate() {
                    for ty in ["Marker", "Marker3"] {
                        let value = Value::Marker {
                            ty,
                            body: k * 997,
                            at,
                        };
                        check(
                            Constant {
                                name: &name,
                                ident: &ident,
                                value,
                            },
                            k < 4,
                        );
                    }
                }
                for i in [0, 7, 123_456] {
                    let value = Value::Index(i);
                    check(
                        Constant {
                            name: &name,
                            ident: &ident,
                            value,
                        },
                        true,
                    );
                }
            }
        }
        // Names of usual lengths are all written by hand (else the
        // writer saves nothing).
        assert_eq!(short_by_hand, short);
        for name in ["a\"b", "a\\b", "tab\there", "é.ü"] {
            let value = Value::Marker {
                ty: "Marker",
                body: 1,
                at: &[1.0, 2.0],
            };
            both(&Constant {
                name,
                ident: "X",
                value,
            });
        }
    }
}
