//! Cross-crate integration tests of the `chatter` workspace (no library code): chatter
//! detection and operational modal analysis (`chatter-oma`, which knows nothing of machining) on
//! records made by the time-domain simulator (`chatter-dynamics`), checked against the
//! stability model's Floquet multipliers and closed-loop poles (`chatter-stability`).
