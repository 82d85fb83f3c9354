//! Every kind of bad input gets one sentence naming what is wrong and the exit
//! code of the contract (2 bad input, 3 no usable driver) — from both apps, and
//! never a panic. One test binary, one module per kind of input; `table` holds
//! one table of every malformed input, so that a reader sees at a glance which
//! inputs are covered and a new case has one home.

mod common;
mod knobs;
mod machine;
mod options;
mod orchestrator;
mod scene_files;
mod table;
