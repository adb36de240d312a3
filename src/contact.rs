//! Instant line of contact.
