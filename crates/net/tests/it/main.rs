//! Tests of the PNML loader and saver.

mod fixtures;
