//! chatter-uncertainty (under construction)
