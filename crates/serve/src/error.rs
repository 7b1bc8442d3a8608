//! The errors of the server: what a request did wrong (a message for the page, HTTP 400), what
//! it asked for that is not there (404), and what went wrong on the server's side (500).

use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};

/// A failed request or start-up.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// The request is wrong: a bad upload, a field out of range, a file that does not parse.
    /// The message names the field and the value and says what was expected.
    #[error("{field}: {message}")]
    BadRequest {
        /// The form field or file.
        field: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// A state-changing request from another origin (the Origin or Host header does not name
    /// this server).
    #[error("cross-origin request refused: {0}")]
    CrossOrigin(String),
    /// The setup, job or cut does not exist.
    #[error("{0} not found")]
    NotFound(String),
    /// The database.
    #[error("database: {0}")]
    Database(#[from] rusqlite::Error),
    /// The data folder.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// A computation of the science crates failed on data the request passed.
    #[error("{0}")]
    Job(String),
}

/// The server's results.
pub type Result<T> = std::result::Result<T, ServeError>;

impl ServeError {
    /// A bad request naming `field`.
    pub fn bad(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self::BadRequest {
            field: field.into(),
            message: message.into(),
        }
    }

    /// An I/O error on `path`.
    pub fn io(path: &std::path::Path, source: std::io::Error) -> Self {
        Self::Io {
            path: path.display().to_string(),
            source,
        }
    }

    fn status(&self) -> StatusCode {
        match self {
            Self::BadRequest { .. } | Self::Job(_) => StatusCode::BAD_REQUEST,
            Self::CrossOrigin(_) => StatusCode::FORBIDDEN,
            Self::NotFound(_) => StatusCode::NOT_FOUND,
            Self::Database(_) | Self::Io { .. } => StatusCode::INTERNAL_SERVER_ERROR,
        }
    }
}

impl IntoResponse for ServeError {
    /// `{"error": message}` with the status; the page shows the message.
    fn into_response(self) -> Response {
        let body = serde_json::json!({ "error": self.to_string() });
        (self.status(), axum::Json(body)).into_response()
    }
}
