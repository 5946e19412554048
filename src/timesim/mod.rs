//! Time-domain reference (todo)
