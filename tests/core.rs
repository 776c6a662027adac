//! The integration tests that need neither the simulator, the command-line tool nor
//! image files, in one binary (`cargo test --test core`; they also run with
//! `--no-default-features`). One module per file beside this one; `arbiter_tracing` and
//! `no_alloc_runtime` stay their own binaries (a process-wide tracing interest, an
//! allocator counting on every thread).

mod common;

mod arbiter;
mod axel_cycle;
mod bujold_phases;
mod common_leaves;
mod components_prop;
mod decision_trace;
mod krawler_kind;
mod krawler_leaves;
mod lockstep;
mod no_alloc;
mod raposa_phases;
mod reactive_loop;
mod runtime;
mod runtime_faults;
mod tree_errors;
mod two_block;
