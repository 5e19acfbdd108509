//! Constant arithmetic folded as the code is written: a product by ±1
//! and a zero added to an input are not written out. Each fold gives the
//! same number as the operation it replaces, bit for bit: `1·x` is `x` and
//! `−1·x` is `−x` for every `x`, and `0 + x` is `x` for every input but
//! `−0.0`, which no sweep or driver makes (it is then `+0.0`, equal to
//! it). Nothing is reassociated: `k·(o + x)` keeps its sum when `o` is not
//! zero.

use proc_macro2::TokenStream;
use quote::quote;

/// `c + x` for a constant `c` (written as `c_tokens`) and an input `x`:
/// `x` alone when `c` is zero.
pub(super) fn plus_input(c: f64, c_tokens: TokenStream, x: TokenStream) -> TokenStream {
    if c == 0.0 {
        x
    } else {
        quote!(#c_tokens + #x)
    }
}

/// `k · x` (on jets and lanes `x.mul_f64(k)`, the same product) for a
/// constant `k`: `x` when `k` is 1, `−x` when it is −1. `compound`: `x`
/// is a sum, to be put in parentheses.
pub(super) fn times(k: f64, x: TokenStream, jets: bool, compound: bool) -> TokenStream {
    let x = if compound { quote!((#x)) } else { x };
    if k == 1.0 {
        x
    } else if k == -1.0 {
        quote!(-#x)
    } else {
        let k = super::lit(k);
        if jets {
            quote!(#x.mul_f64(#k))
        } else {
            quote!(#k * #x)
        }
    }
}
