//! chatter-bayes (under construction)
