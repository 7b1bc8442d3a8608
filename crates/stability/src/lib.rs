//! chatter-stability (under construction)
