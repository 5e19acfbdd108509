//! Rules the source keeps, read from the files: the layers point one way
//! and no function is longer than a reader can hold. One test binary for
//! both.

mod function_length;
mod layers;
