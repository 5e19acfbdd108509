//! The scaffold of every generated module, planar or spatial, written
//! once from a [`Scaffold`] (what a plan names: bodies, markers, inputs,
//! the state's fields) and a [`Dimension`] (pose, point and marker types,
//! the runtime's rates trait): the constants, `State` and its drawn value,
//! the `body` and `marker` modules, and `Plan` with its `Solver`, rates and
//! `Batch` impls. Each back end writes its imports and steps around it.
//!
//! The rates API is written here too: the module functions
//! `solve_rates_into`, `solve_rates` and `rates`, and the `Rates`
//! trait methods, around each back end's body of `solve_rates_into` (its
//! steps on jets).
//!
//! The body writes the poses straight into the caller's `out`: a frame
//! with rates moves a dozen jets per body, and returning them by value
//! copied them twice more (into the result, then into `out`), a fifth of
//! a small plan's frame.

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::constants::{Constant, Value};
use super::{index, names, Sink};
use crate::model::InputKind;

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

/// The `Rates` trait methods of the module's `Plan`: the module
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

/// What the scaffold of a module names differently in each dimension.
pub(super) struct Dimension {
    /// The pose type (`Pose`, `Pose3`).
    pub pose: TokenStream,
    /// A world point (`Point`, `Vec3`).
    pub point: TokenStream,
    /// A marker constant (`Marker`, `Marker3`).
    pub marker: TokenStream,
}

impl Dimension {
    /// Planar modules: `dofplan_runtime::planar` poses.
    pub fn planar() -> Dimension {
        Dimension {
            pose: quote!(Pose),
            point: quote!(Point),
            marker: quote!(Marker),
        }
    }

    /// Spatial modules: `dofplan_runtime::spatial` poses.
    pub fn spatial() -> Dimension {
        Dimension {
            pose: quote!(Pose3),
            point: quote!(Vec3),
            marker: quote!(Marker3),
        }
    }
}

/// A field of `State` after its poses: what a frame of the dimension's
/// steps carries to the next besides them.
pub(super) struct Field {
    /// Its doc comment (each line with its leading space).
    pub doc: &'static [&'static str],
    /// Its name.
    pub name: &'static str,
    /// Its type.
    pub ty: TokenStream,
    /// Its value in the drawn pose.
    pub drawn: TokenStream,
}

/// What one module's scaffold is written from.
pub(super) struct Scaffold<'a> {
    /// The dimension's types.
    pub dim: Dimension,
    /// The mechanism's name.
    pub name: &'a str,
    /// Body names, in plan order.
    pub bodies: Vec<&'a str>,
    /// Which bodies are fixed.
    pub fixed: Vec<bool>,
    /// Inputs: name and kind, in plan order.
    pub inputs: Vec<(&'a str, InputKind)>,
    /// The number of plan steps.
    pub steps: usize,
    /// Each marker: its body, its name (`coupler.B`) and its local
    /// coordinates.
    pub markers: Vec<(usize, String, &'a [f64])>,
    /// The state's fields after `poses`.
    pub fields: Vec<Field>,
    /// For a plan whose frames are independent (a closed-form plan): how
    /// its module's own `solve_batch` and `solve_frames` solve them ("in
    /// lanes"), which the `Batch` impl calls. `None`: frames in order.
    pub independent: Option<&'static str>,
}

/// The kind of an input, as the generated module writes it.
fn input_kind(kind: InputKind) -> TokenStream {
    match kind {
        InputKind::Angle => quote!(InputKind::Angle),
        InputKind::Slide => quote!(InputKind::Slide),
    }
}

/// The doc comment of `solve`, for `inputs` (name and kind).
pub(super) fn doc_solve<'a>(inputs: impl ExactSizeIterator<Item = (&'a str, InputKind)>) -> String {
    let inputs = if inputs.len() == 0 {
        "none".to_string()
    } else {
        inputs
            .map(|(name, kind)| {
                let unit = match kind {
                    InputKind::Angle => "degrees",
                    InputKind::Slide => "length units",
                };
                format!("{name} in {unit}")
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    format!(" Places every body for `inputs` ({inputs}), warm-started from `s`. On a break `s` is left unchanged.")
}

/// The module's header comment: `what` is "mechanism `fourbar`: 5 steps, …".
pub(super) fn header(source: &str, what: &str) -> String {
    format!(
        "// @generated by dofplan from {source} — do not edit.\n// Compiled plan of {what}.\n// Regenerate with `dofplan emit {source}` or by rebuilding the crate that compiles it.\n\n"
    )
}

impl Scaffold<'_> {
    /// `imports`, then the constants, `State` with its drawn value, and the
    /// `body` and `marker` modules: everything up to `Plan`.
    pub fn head(&self, imports: TokenStream, sink: &mut Sink) {
        let Dimension { pose, .. } = &self.dim;
        let name = self.name;
        let nb = index(self.bodies.len());
        let ni = index(self.inputs.len());
        let nsteps = index(self.steps);
        let body_names = &self.bodies;
        let fixed = &self.fixed;
        let input_names = self.inputs.iter().map(|(n, _)| n);
        let input_kinds = self.inputs.iter().map(|&(_, k)| input_kind(k));
        let fields = self.fields.iter().map(|f| {
            let (doc, name, ty) = (f.doc, format_ident!("{}", f.name), &f.ty);
            quote! {
                #(#[doc = #doc])*
                pub #name: #ty,
            }
        });
        let drawn = self.fields.iter().map(|f| {
            let (name, value) = (format_ident!("{}", f.name), &f.drawn);
            quote!(#name: #value,)
        });
        sink.push(quote! {
            #imports

            /// Kind of an input.
            pub use dofplan_runtime::planar::InputKind;

            /// The mechanism's name.
            pub const NAME: &str = #name;
            /// Body names, in the order of [`State::poses`].
            pub const BODIES: [&str; #nb] = [#(#body_names),*];
            /// Which bodies are fixed (ground).
            pub const FIXED: [bool; #nb] = [#(#fixed),*];
            /// Input names, in the order [`solve`] takes them.
            pub const INPUTS: [&str; #ni] = [#(#input_names),*];
            /// Input kinds (angles in degrees, slides in length units).
            pub const INPUT_KINDS: [InputKind; #ni] = [#(#input_kinds),*];
            /// Number of plan steps.
            pub const STEPS: usize = #nsteps;

            /// What a frame reads from the previous one and writes.
            #[derive(Clone, Copy, Debug, PartialEq)]
            pub struct State {
                /// Body poses, in [`BODIES`] order.
                pub poses: [#pose; #nb],
                #(#fields)*
            }

            impl State {
                /// The drawn pose.
                pub const DRAWN: State = State {
                    poses: [#pose::IDENTITY; #nb],
                    #(#drawn)*
                };
            }
        });
        self.names(sink);
    }

    /// The constants naming each body and marker, and the state's marker
    /// reader, into `sink`; the two modules of constants a batch of
    /// constants at a time (a chain of 20,000 loops has 120,000 markers).
    fn names(&self, sink: &mut Sink) {
        let Dimension { point, marker, .. } = &self.dim;
        let body_names = names::constants(self.bodies.iter().copied());
        let bodies = (self.bodies.iter().zip(&body_names).enumerate()).map(|(i, (b, c))| {
            let value = Value::Index(i);
            Constant {
                name: b,
                ident: c,
                value,
            }
            .laid_out()
        });
        let marker_names = names::constants(self.markers.iter().map(|(_, n, _)| n.as_str()));
        let ty = marker.to_string();
        let markers = self.markers.iter().zip(&marker_names).map(|((b, name, at), c)| {
            let value = Value::Marker {
                ty: &ty,
                body: *b,
                at,
            };
            Constant {
                name,
                ident: c,
                value,
            }
            .laid_out()
        });
        let use_marker = if self.markers.is_empty() {
            quote!()
        } else {
            quote!(
                use dofplan_runtime::#marker;
            )
        };
        sink.push_module(
            quote! {
                /// Each body's index in [`BODIES`] and [`State::poses`], by name:
                /// upper-cased, other characters than ASCII letters and digits
                /// made `_`, and `_2`, `_3`, … after a name an earlier body took.
                pub mod body
            },
            quote!(),
            bodies,
        );
        let doc = format!(" `State::marker` or `{marker}::world`.");
        sink.push_module(
            quote! {
                /// Each marker's body and local coordinates (its drawn position),
                /// named `BODY_MARKER` by the rule of `body`; read one with
                #[doc = #doc]
                pub mod marker
            },
            use_marker,
            markers,
        );
        sink.push(quote! {
            impl State {
                /// The world position of marker `m` (a constant of
                /// [`marker`]) in this state.
                #[inline]
                pub fn marker(&self, m: #marker) -> #point {
                    m.world(&self.poses)
                }
            }
        });
    }

    /// `Plan` and its impls: `Solver` (by the module's `solve`), the rates
    /// trait (by `solve_rates_into`) and `Batch` (by the module's
    /// `solve_batch`, and `solve_frames` when the frames are independent;
    /// written here when they are not: the frames in order).
    pub fn plan(&self, sink: &mut Sink) {
        let Dimension { pose, .. } = &self.dim;
        let ni = index(self.inputs.len());
        let rate_methods = rates_trait_methods(pose);
        let batch_impl = if let Some(how) = self.independent {
            let doc = format!(
                " Frames of a closed-form plan are independent: solved {how}, and on several cores by"
            );
            quote! {
                #[doc = #doc]
                /// `dofplan_runtime::batch::solve_batch_parallel`.
                impl dofplan_runtime::Batch for Plan {
                    fn independent(&self) -> bool {
                        true
                    }

                    fn solve_batch(&self, inputs: &[f64], out: &mut [#pose], status: &mut [dofplan_runtime::FrameStatus]) {
                        self::solve_batch(inputs, out, status)
                    }

                    fn solve_frames(&self, inputs: &[f64], out: &mut [#pose], status: &mut [dofplan_runtime::FrameStatus]) {
                        self::solve_frames(inputs, out, status)
                    }
                }
            }
        } else {
            quote! {
                /// Frames solved in order, each warm-started from the last.
                impl dofplan_runtime::Batch for Plan {
                    fn solve_batch(&self, inputs: &[f64], out: &mut [#pose], status: &mut [dofplan_runtime::FrameStatus]) {
                        self::solve_batch(inputs, out, status)
                    }
                }

                /// Every frame of `inputs` (one row of [`INPUTS`] values a
                /// frame) into `out` (one row of [`BODIES`] poses a frame),
                /// with the driver's results in `status`: in order, each
                /// frame warm-started from the last, as a
                /// [`dofplan_runtime::Driver`] runs them (keep-branch and
                /// limit policies, from the drawn pose).
                ///
                /// # Panics
                /// If `inputs` or `out` is not `status.len()` rows long.
                pub fn solve_batch(inputs: &[f64], out: &mut [#pose], status: &mut [dofplan_runtime::FrameStatus]) {
                    dofplan_runtime::batch::in_order(&Plan, inputs, out, status)
                }
            }
        };
        sink.push(quote! {
            /// The compiled plan, for [`dofplan_runtime::Driver`].
            #[derive(Clone, Copy, Debug, Default)]
            pub struct Plan;

            impl Solver for Plan {
                type Pose = #pose;
                type State = State;
                type Inputs = [f64; #ni];

                fn initial_state(&self) -> State {
                    State::DRAWN
                }

                fn initial_inputs(&self) -> [f64; #ni] {
                    [0.0; #ni]
                }

                fn poses(state: &State) -> &[#pose] {
                    &state.poses
                }

                fn solve(&self, s: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                    solve(s, inputs, ctx)
                }
            }

            impl dofplan_runtime::real::Rates for Plan {
                #rate_methods
            }

            #batch_impl
        });
    }
}
