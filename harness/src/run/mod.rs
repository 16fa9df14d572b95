//! Running a plan: the runner that fills the cells of a sweep ([`runner`], [`cell`], [`interleave`]),
//! the execution of a whole experiment from plan to result files ([`execute`]), progress and time
//! accounting ([`progress`], [`cputime`], [`phases`]), resuming an interrupted run ([`resume`]),
//! splitting a sweep over machines and joining it again ([`shard`], [`merge`]), and estimates taken
//! outside the runner ([`guarded`]).

pub mod cell;
pub mod cputime;
pub mod execute;
pub mod guarded;
pub mod interleave;
pub mod merge;
pub mod phases;
pub mod progress;
pub mod resume;
pub mod runner;
pub mod shard;
