//! The rates API of every generated module, planar or spatial: the module
//! functions `solve_rates_into`, `solve_rates` and `rates`, and the
//! `Rates`/`Rates3` trait methods, around each back end's body of
//! `solve_rates_into` (its steps on jets).
//!
//! The body writes the poses straight into the caller's `out`: a frame
//! with rates moves a dozen jets per body, and returning them by value
//! copied them twice more (into the result, then into `out`), a fifth of
//! a small plan's frame.

use proc_macro2::{Literal, TokenStream};
use quote::quote;

/// The module functions around `body`, which has `s: &mut State`,
/// `inputs`, `rates`, `accelerations: &[f64]`, `ctx: &mut Ctx` and
/// `out: &mut [#pose<Jet2>; #nb]` in scope, places every body into `out`
/// and evaluates to `Result<(), RateError>`. `pose` is the pose type
/// (`Pose` or `Pose3`).
pub(super) fn rates_functions(pose: &TokenStream, nb: &Literal, body: TokenStream) -> TokenStream {
    quote! {
        /// [`solve`] and [`rates`] in one pass, into `out` (one pose a
        /// body): every body placed for `inputs`, warm-started from `s`,
        /// with its first and second derivatives along `rates` and
        /// `accelerations` (per second, in the inputs' units: degrees for
        /// angles) — the steps run once, on [`Jet2`]s, whose values are
        /// exactly `solve`'s. On a break `s` is left unchanged
        /// ([`RateError::Break`]); at a dead point, where a rate is
        /// infinite, the frame is committed (its positions are exact) and
        /// the rates are [`RateError::Singular`]. On an error `out` holds
        /// no poses to read.
        pub fn solve_rates_into(
            s: &mut State,
            inputs: &[f64],
            rates: &[f64],
            accelerations: &[f64],
            ctx: &mut Ctx,
            out: &mut [#pose<Jet2>; #nb],
        ) -> Result<(), RateError> {
            #body
        }

        /// [`solve_rates_into`], returning the poses.
        pub fn solve_rates(
            s: &mut State,
            inputs: &[f64],
            rates: &[f64],
            accelerations: &[f64],
            ctx: &mut Ctx,
        ) -> Result<[#pose<Jet2>; #nb], RateError> {
            let mut out = [#pose::<Jet2>::cst(#pose::IDENTITY); #nb];
            solve_rates_into(s, inputs, rates, accelerations, ctx, &mut out)?;
            Ok(out)
        }

        /// Every body's pose at the frame `s` was solved to (at
        /// `inputs`) with its first and second derivatives along the
        /// inputs' `rates` and `accelerations` (per second, in the
        /// inputs' units: degrees for angles): the steps of [`solve`]
        /// run again on [`Jet2`]s — forward-mode differentiation through
        /// the plan — with the branches the frame took. A dead point,
        /// where a rate is infinite, is [`RateError::Singular`].
        pub fn rates(
            s: &State,
            inputs: &[f64],
            rates: &[f64],
            accelerations: &[f64],
        ) -> Result<[#pose<Jet2>; #nb], RateError> {
            // Solving a frame's own inputs again from it gives the same
            // roots under keep-branch, so these are the rates of the roots
            // it took.
            let mut again = *s;
            solve_rates(&mut again, inputs, rates, accelerations, &mut Ctx::new(BranchPolicy::Keep, false))
        }
    }
}

/// The `Rates`/`Rates3` trait methods of the module's `Plan`: the module
/// functions on the trait's slices.
pub(super) fn rates_trait_methods(pose: &TokenStream) -> TokenStream {
    quote! {
        fn rates_into(
            &self,
            s: &State,
            inputs: &[f64],
            rates: &[f64],
            accelerations: &[f64],
            out: &mut [#pose<Jet2>],
        ) -> Result<(), RateError> {
            let mut again = *s;
            let ctx = &mut Ctx::new(BranchPolicy::Keep, false);
            let out = out.try_into().expect("`out` has one pose per body");
            self::solve_rates_into(&mut again, inputs, rates, accelerations, ctx, out)
        }

        fn solve_rates_into(
            &self,
            s: &mut State,
            inputs: &[f64],
            rates: &[f64],
            accelerations: &[f64],
            ctx: &mut Ctx,
            out: &mut [#pose<Jet2>],
        ) -> Result<(), RateError> {
            let out = out.try_into().expect("`out` has one pose per body");
            self::solve_rates_into(s, inputs, rates, accelerations, ctx, out)
        }
    }
}
