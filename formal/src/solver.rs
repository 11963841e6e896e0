//! The SMT solver driver.
