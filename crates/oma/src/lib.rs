//! chatter-oma (under construction)
