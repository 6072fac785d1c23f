//! An example of a user's crate that tests its scenes with sunshade; the tests are in `tests/`.
//!
//! ```text
//! cargo test --release -p sunshade-golden-test-example                   # compare with the goldens
//! UPDATE_GOLDENS=1 cargo test --release -p sunshade-golden-test-example  # rewrite them after a deliberate change
//! ```
