//! End-to-end tests of the `mpcontact` binary live in `tests/tests/`.
