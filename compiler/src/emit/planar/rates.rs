//! The planar steps on jets and lanes: `solve_rates` (a frame and its
//! rates in one pass) and `solve_lanes` with the batch functions around
//! it (frames side by side, for `solve_batch`).

use proc_macro2::TokenStream;
use quote::quote;

use super::{index, uses, Emitter};

impl Emitter<'_> {
    /// The state's last roots lifted to `real` (`Jet2` or `Lanes`), slot by
    /// slot rather than by `s.last.map(..)`, which stays a call: in a plan
    /// of a few steps that call is a fifth of a frame on jets, and on lanes
    /// (which only write `last`, under keep-branch) the stores into an
    /// array nothing reads are then dropped.
    pub(super) fn lifted_last(&self, real: TokenStream) -> TokenStream {
        let k = (0..self.plan.branches.len()).map(index);
        quote!([#(planar::cst::<#real>(s.last[#k])),*])
    }

    /// The steps with each placed body's working pose (on `real`: `Jet2`
    /// or `Lanes`) declared just before the first step that names it, not
    /// all at the top: their lifetimes then overlap little, so the compiler
    /// can give them the same stack slots (a chain of 50 bodies otherwise
    /// keeps 12.8 KB of lanes alive, and its stack frame no longer fits the
    /// data cache). `after(i)` follows step `i`.
    pub(super) fn declared_late(
        &self,
        steps: Vec<TokenStream>,
        real: TokenStream,
        after: impl Fn(usize) -> TokenStream,
    ) -> Vec<TokenStream> {
        let uses: Vec<uses::Uses> = steps.iter().map(uses::Uses::of).collect();
        let first_use: Vec<(usize, usize)> = self
            .written_bodies()
            .into_iter()
            .filter_map(|b| {
                let id = self.pose_idents[b].to_string();
                uses.iter().position(|u| u.has(&id)).map(|i| (b, i))
            })
            .collect();
        steps
            .into_iter()
            .enumerate()
            .map(|(i, step)| {
                let takes = first_use.iter().filter(|&&(_, f)| f == i).map(|&(b, _)| {
                    let (id, k) = (&self.pose_idents[b], index(b));
                    quote!(let mut #id = Pose::<#real>::cst(s.poses[#k]);)
                });
                let after = after(i);
                quote!(#(#takes)* #step #after)
            })
            .collect()
    }

    /// `out[b] = …` for every body at the end of a pass on `real` (`Jet2`
    /// or the design module's `Dual`): its working pose, or the state's
    /// for a body no step places.
    pub(super) fn pose_outputs(&self, real: TokenStream) -> Vec<TokenStream> {
        let written = self.written_bodies();
        (0..self.plan.bodies.len())
            .map(|b| {
                let i = index(b);
                if written.contains(&b) {
                    let id = &self.pose_idents[b];
                    quote!(out[#i] = #id;)
                } else {
                    quote!(out[#i] = Pose::<#real>::cst(s.poses[#i]);)
                }
            })
            .collect()
    }

    /// `solve_rates`: a frame and its rates in one pass on jets (their
    /// values are `solve`'s, the same operations on the same numbers),
    /// committed to `s` as `solve` commits.
    pub(super) fn solve_rates_fn(&self, steps: Vec<TokenStream>) -> TokenStream {
        let plan = self.plan;
        let written = self.written_bodies();
        let steps = self.declared_late(steps, quote!(Jet2), |_| quote!());
        let commit = written.iter().map(|&b| {
            let (id, i) = (&self.pose_idents[b], index(b));
            quote!(s.poses[#i] = #id.value();)
        });
        let out = self.pose_outputs(quote!(Jet2));
        let (take_branches, commit_branches) = if plan.branches.is_empty() {
            (quote!(), quote!())
        } else {
            let last = self.lifted_last(quote!(Jet2));
            let k = (0..plan.branches.len()).map(index);
            (
                quote!(let mut last = #last; let mut branches = s.branches;),
                quote!(#(s.last[#k] = [last[#k][0].v, last[#k][1].v];)* s.branches = branches;),
            )
        };
        let bind_inputs = (0..plan.inputs.len()).map(|k| self.bind_input(k));
        let (nb, ni) = (index(plan.bodies.len()), index(plan.inputs.len()));
        let body = quote! {
            let inputs: [Jet2; #ni] =
                core::array::from_fn(|k| Jet2::new(inputs[k], rates[k], accelerations[k]));
            let _ = (&inputs, &ctx);
            #take_branches
            #(#bind_inputs)*
            #(#steps)*
            #(#commit)*
            #commit_branches
            #(#out)*
            real::checked(&*out).map(|_| ())
        };
        super::scaffold::rates_functions(&quote!(Pose), &nb, body)
    }

    /// `solve_lanes`: [`LANES`](dofplan_runtime::lanes::LANES) frames at
    /// once from the drawn pose (keep-branch, no stretching), for
    /// `solve_batch`.
    pub(super) fn solve_lanes_fn(&self, steps: Vec<TokenStream>) -> TokenStream {
        let (nb, ni) = (index(self.plan.bodies.len()), index(self.plan.inputs.len()));
        let body = self.lanes_body(steps);
        let batch = batch_functions();
        quote! {
        /// [`solve`] of [`LANES`](dofplan_runtime::lanes::LANES) frames
        /// side by side (lane `l` of every input is frame `l`'s; frame
        /// `l`'s poses go to `rows[l]`, each body's as soon as its last
        /// step has placed it), each
        /// from the drawn pose under keep-branch: the frames of a
        /// closed-form plan do not depend on each other. A break in any
        /// frame, or frames that part ways at a step
        /// ([`BreakKind::LanesDiffer`](dofplan_runtime::BreakKind::LanesDiffer)),
        /// is an error for all of them: [`solve_batch`] then solves
        /// them one at a time.
        #[inline(always)]
        pub fn solve_lanes(inputs: &[Lanes; #ni], rows: &mut [[Pose; #nb]; dofplan_runtime::lanes::LANES]) -> Result<(), Break> {
            let s = &State::DRAWN;
            #body
        }

        #batch        }
    }

    /// The body of a function running the steps on lanes of frames from
    /// the state `s` (the drawn one, or a design candidate's), each body's
    /// poses put into `rows` after the last step that places it.
    pub(super) fn lanes_body(&self, steps: Vec<TokenStream>) -> TokenStream {
        let plan = self.plan;
        let written = self.written_bodies();
        // Each body goes to the rows right after the last step that places
        // it; the bodies no step places (ground, idle ones), first.
        let last_write = self.last_writes();
        let put = |b: usize| {
            let i = index(b);
            if written.contains(&b) {
                let id = &self.pose_idents[b];
                quote!(dofplan_runtime::batch::put_body(&#id, rows, #i);)
            } else {
                quote!(dofplan_runtime::batch::put_body(&Pose::<Lanes>::cst(s.poses[#i]), rows, #i);)
            }
        };
        let unplaced = (0..plan.bodies.len()).filter(|&b| !written.contains(&b)).map(put);
        let steps = self.declared_late(steps, quote!(Lanes), |i| {
            let puts = (0..plan.bodies.len())
                .filter(|&b| written.contains(&b) && last_write[b] == Some(i))
                .map(put);
            quote!(#(#puts)*)
        });
        let take_branches = if plan.branches.is_empty() {
            quote!()
        } else {
            let last = self.lifted_last(quote!(Lanes));
            quote!(let mut last = #last; let mut branches = s.branches;)
        };
        let bind_inputs = (0..plan.inputs.len()).map(|k| self.bind_input(k));
        quote! {
            let ctx = &mut Ctx::new(dofplan_runtime::BranchPolicy::Keep, false);
            let _ = (&inputs, &ctx);
            #(#unplaced)*
            #take_branches
            #(#bind_inputs)*
            #(#steps)*
            Ok(())
        }
    }
}

/// `solve_batch` and what it calls, the same for every planar plan: the
/// frames through `solve_lanes` a lane group at a time (AVX2 where the CPU
/// has it), the rest one at a time, then the holds past limits.
fn batch_functions() -> TokenStream {
    quote! {
        /// Every frame of `inputs` (one row of [`INPUTS`] values a
        /// frame) into `out` (one row of [`BODIES`] poses a frame),
        /// with the driver's results (keep-branch and limit policies,
        /// from the drawn pose) in `status`:
        /// [`LANES`](dofplan_runtime::lanes::LANES) frames at a time
        /// through [`solve_lanes`].
        ///
        /// # Panics
        /// If `inputs` or `out` is not `status.len()` rows long.
        pub fn solve_batch(inputs: &[f64], out: &mut [Pose], status: &mut [dofplan_runtime::FrameStatus]) {
            solve_frames(inputs, out, status);
            dofplan_runtime::batch::settle(&Plan, inputs, out, status)
        }

        /// Every frame of `inputs` on its own, from the drawn pose, as
        /// [`solve_batch`] solves them before the holds past limits
        /// (`dofplan_runtime::batch::settle`).
        ///
        /// # Panics
        /// If `inputs` or `out` is not `status.len()` rows long.
        pub fn solve_frames(inputs: &[f64], out: &mut [Pose], status: &mut [dofplan_runtime::FrameStatus]) {
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: this CPU has AVX2, checked just above.
                return unsafe { solve_batch_avx2(inputs, out, status) };
            }
            solve_batch_baseline(inputs, out, status)
        }

        /// [`solve_frames`] for any CPU. Its own function, as the AVX2
        /// one is, so that `solve_frames` does not hold a frame of lane
        /// temporaries on the stack beside the one it calls (unoptimised
        /// builds give every temporary a slot of its own).
        #[inline(never)]
        fn solve_batch_baseline(inputs: &[f64], out: &mut [Pose], status: &mut [dofplan_runtime::FrameStatus]) {
            batch_in_lanes(inputs, out, status)
        }

        /// [`solve_frames`] compiled for AVX2: a lane group in two
        /// registers instead of four. The same operations in the same
        /// order (no fused multiply-add), so the same numbers.
        ///
        /// # Safety
        /// The CPU must have AVX2.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        unsafe fn solve_batch_avx2(inputs: &[f64], out: &mut [Pose], status: &mut [dofplan_runtime::FrameStatus]) {
            batch_in_lanes(inputs, out, status)
        }

        /// The lane groups through [`solve_lanes`], the rest one frame
        /// at a time (see `dofplan_runtime::batch::lane_groups`).
        #[inline(always)]
        fn batch_in_lanes(inputs: &[f64], out: &mut [Pose], status: &mut [dofplan_runtime::FrameStatus]) {
            use dofplan_runtime::batch;
            let groups = batch::lane_groups(&Plan, inputs, out, status);
            for g in 0..groups {
                match solve_lanes(&batch::group_inputs(inputs, g), batch::group_rows(out, g)) {
                    // A group that does not finish leaves its rows partly
                    // written: solving its frames one at a time rewrites
                    // them (and `settle` holds those that break).
                    Ok(()) => batch::solved(status, g),
                    Err(_) => {
                        let lanes = dofplan_runtime::lanes::LANES;
                        batch::one_at_a_time(&Plan, g * lanes..(g + 1) * lanes, inputs, out, status)
                    }
                }
            }
            batch::finish(&Plan, groups * dofplan_runtime::lanes::LANES, inputs, out, status);
        }
    }
}
