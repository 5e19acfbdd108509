//! The spatial steps on jets: `solve_rates` and `rates`, in one function
//! or in the chunks of `solve`.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::Emitter;
use crate::emit::index;
use crate::emit::uses::Uses;

impl Emitter<'_> {
    /// `solve_rates` and `rates`: the steps written on jets (`steps`; a
    /// numeric cluster's by the implicit function theorem), run in one
    /// function or, for a plan split into functions (`chunks`), in the
    /// same chunks as `solve`'s.
    pub(super) fn rates(&self, steps: Vec<TokenStream>, chunks: Option<&[(usize, usize)]>) -> TokenStream {
        let plan = self.plan;
        let nb = index(plan.bodies.len());
        // The steps in `run_jets` itself, or in functions of the chunks of
        // `solve` that it calls.
        let (body, functions) = match chunks {
            None => (steps, Vec::new()),
            Some(chunks) => {
                let mut steps = steps.into_iter();
                let (mut calls, mut functions) = (Vec::new(), Vec::new());
                for &(first, last) in chunks {
                    let code: Vec<TokenStream> = steps.by_ref().take(last - first + 1).collect();
                    let u = Uses::of(&quote!(#(#code)*));
                    let param = |name: &str| {
                        if u.has(name) {
                            format_ident!("{}", name)
                        } else {
                            format_ident!("_{}", name)
                        }
                    };
                    let (inputs, values, ctx) = (param("inputs"), param("input_values"), param("ctx"));
                    let (f, fdoc) = if first == last {
                        (
                            format_ident!("jets_step_{}", first),
                            format!(" Step {first} of [`solve`] on jets, in place."),
                        )
                    } else {
                        (
                            format_ident!("jets_steps_{}_to_{}", first, last),
                            format!(" Steps {first} to {last} of [`solve`] on jets, in place."),
                        )
                    };
                    functions.push(quote! {
                        #[doc = #fdoc]
                        #[inline(never)]
                        fn #f(w: &mut Jets<'_>, #inputs: &[Jet2], #values: &[f64], #ctx: &mut Ctx) -> Result<(), Break> {
                            #(#code)*
                            Ok(())
                        }
                    });
                    calls.push(quote!(#f(w, inputs, input_values, ctx)?;));
                }
                (calls, functions)
            }
        };
        let steps = body;
        let (nt, nk, ni) = (
            index(plan.temps.len()),
            index(plan.branches.len()),
            index(plan.inputs.len()),
        );
        let moving = (0..plan.bodies.len()).filter(|&b| plan.composes(b)).map(|b| {
            let b = index(b);
            quote!(w.poses[#b].renormalize();)
        });
        // The steps work on the poses in `out` itself.
        let body = quote! {
            let jets: [Jet2; #ni] =
                core::array::from_fn(|k| Jet2::new(inputs[k], rates[k], accelerations[k]));
            for (o, p) in out.iter_mut().zip(&s.poses) {
                *o = Pose3::cst(*p);
            }
            let mut w = Jets {
                poses: out,
                temps: s.temps.map(spatial::cst),
                branches: s.branches,
                angles: s.angles,
            };
            run_jets(&mut w, &jets, inputs, ctx)?;
            for (p, o) in s.poses.iter_mut().zip(w.poses.iter()) {
                *p = o.value();
            }
            s.temps = w.temps.map(spatial::value);
            s.branches = w.branches;
            s.angles = w.angles;
            spatial::checked3(&*w.poses).map(|_| ())
        };
        let api = super::scaffold::rates_functions(&quote!(Pose3), &nb, body);
        let code = quote! {
            /// [`State`] on jets: what [`solve_rates`] works on, its poses
            /// in the caller's `out`.
            struct Jets<'a> {
                poses: &'a mut [Pose3<Jet2>; #nb],
                temps: [Vec3<Jet2>; #nt],
                branches: [Branch; #nk],
                angles: [f64; #nk],
            }

            #api

            /// Every step of [`solve`] on jets, in place (checks on
            /// `input_values`).
            #[inline(always)]
            fn run_jets(w: &mut Jets<'_>, inputs: &[Jet2], input_values: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                let _ = (&w, &inputs, &input_values, &ctx);
                #(#steps)*
                #(#moving)*
                Ok(())
            }

            #(#functions)*
        };
        code
    }
}
