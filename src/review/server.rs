//! The review server: the page and its files on 127.0.0.1, and the accept and reject actions,
//! one request at a time (a reviewer clicks one button at a time, and decisions must not race).
//!
//! It is `tiny_http`, a small synchronous server: no async runtime for a page that one person
//! opens on their own machine. Every request goes through [`route`] first; what it may do is
//! listed there.

use std::net::{Ipv4Addr, SocketAddr};

use serde_json::json;

use super::decide::{Decision, accept, accept_all, reject};
use super::error::ReviewError;
use super::page::Resources;
use super::pending::{Project, relative};
use super::requests::{Refusal, Route, route};
use super::review_project;
use super::site::Site;

/// What the server did, for the caller to log.
#[derive(Debug)]
pub enum Event {
    Decided(Decision),
    Refused {
        method: String,
        url: String,
        refusal: Refusal,
    },
    /// A request that could not be answered as asked (the reason is also the answer).
    Failed {
        url: String,
        message: String,
    },
}

pub struct Server {
    http: tiny_http::Server,
    address: SocketAddr,
}

impl Server {
    /// Listens on 127.0.0.1 (never another interface) at `port`, or a free port for 0.
    pub fn bind(port: u16) -> Result<Server, ReviewError> {
        let wanted = SocketAddr::from((Ipv4Addr::LOCALHOST, port));
        let failed = |message: String| ReviewError::Serve {
            address: wanted.to_string(),
            message,
        };
        let http = tiny_http::Server::http(wanted).map_err(|e| failed(e.to_string()))?;
        let address = http
            .server_addr()
            .to_ip()
            .ok_or_else(|| failed("not an IP socket".to_owned()))?;
        Ok(Server { http, address })
    }

    /// The page's address, `http://127.0.0.1:PORT/`.
    pub fn url(&self) -> String {
        format!("http://{}/", self.address)
    }

    /// Answers requests until the process ends, reporting each decision and refusal to `log`.
    pub fn serve(&self, project: &Project, mut log: impl FnMut(Event)) -> Result<(), ReviewError> {
        let mut site = build(project)?;
        loop {
            let request = self.http.recv().map_err(|e| ReviewError::Serve {
                address: self.address.to_string(),
                message: e.to_string(),
            })?;
            let (status, body, kind) = self.answer(&request, project, &mut site, &mut log);
            let response = tiny_http::Response::from_data(body).with_status_code(status);
            let response = [
                ("Content-Type", kind),
                ("X-Content-Type-Options", "nosniff"),
                ("Cache-Control", "no-store"),
                ("X-Frame-Options", "DENY"),
                ("Referrer-Policy", "no-referrer"),
            ]
            .into_iter()
            .filter_map(|(name, value)| tiny_http::Header::from_bytes(name, value).ok())
            .fold(response, |response, header| response.with_header(header));
            // A browser that went away before its answer is no reason to stop serving.
            let _ = request.respond(response);
        }
    }

    fn answer(
        &self,
        request: &tiny_http::Request,
        project: &Project,
        site: &mut Site,
        log: &mut impl FnMut(Event),
    ) -> (u16, Vec<u8>, &'static str) {
        let header = |name: &str| {
            request
                .headers()
                .iter()
                .find(|h| h.field.as_str().as_str().eq_ignore_ascii_case(name))
                .map(|h| h.value.as_str().to_owned())
        };
        let method = request.method().as_str().to_owned();
        let url = request.url().to_owned();
        let route = match route(&method, &url, header, self.address.port()) {
            Ok(route) => route,
            Err(refusal) => {
                let body = error_json(&refusal.reason);
                let status = refusal.status;
                log(Event::Refused { method, url, refusal });
                return (status, body, JSON);
            }
        };
        let failed = |log: &mut dyn FnMut(Event), status: u16, error: ReviewError| {
            let message = error.to_string();
            log(Event::Failed {
                url: url.clone(),
                message: message.clone(),
            });
            (status, error_json(&message), JSON)
        };
        let decided = |decisions: Vec<Decision>, site: &mut Site, log: &mut dyn FnMut(Event)| {
            let shown =
                |paths: &[std::path::PathBuf]| paths.iter().map(|p| relative(&project.root, p)).collect::<Vec<_>>();
            let answer = json!({
                "decisions": decisions.iter().map(|d| json!({
                    "name": d.name,
                    "accepted": d.accepted,
                    "written": shown(&d.written),
                    "removed": shown(&d.removed),
                })).collect::<Vec<_>>()
            });
            for decision in decisions {
                site.forget(&decision.name);
                log(Event::Decided(decision));
            }
            (200, answer.to_string().into_bytes(), JSON)
        };
        match route {
            Route::Page => match build(project) {
                Ok(fresh) => {
                    *site = fresh;
                    (200, site.index().to_vec(), "text/html; charset=utf-8")
                }
                Err(error) => failed(log, 500, error),
            },
            Route::File(path) => match site.get(&path) {
                Some((bytes, kind)) => (200, bytes.to_vec(), kind),
                None => (404, error_json("no such file"), JSON),
            },
            Route::Accept(name) => match accept(project, &name) {
                Ok(decision) => decided(vec![decision], site, log),
                Err(error) => failed(log, status_of(&error), error),
            },
            Route::Reject(name) => match reject(project, &name) {
                Ok(decision) => decided(vec![decision], site, log),
                Err(error) => failed(log, status_of(&error), error),
            },
            Route::AcceptAll => match accept_all(project) {
                Ok(decisions) => decided(decisions, site, log),
                Err(error) => failed(log, status_of(&error), error),
            },
        }
    }
}

const JSON: &str = "application/json";

fn status_of(error: &ReviewError) -> u16 {
    match error {
        ReviewError::NotPending { .. } => 404,
        _ => 500,
    }
}

fn error_json(message: &str) -> Vec<u8> {
    json!({ "error": message }).to_string().into_bytes()
}

/// The page of the goldens pending now, with its buttons.
fn build(project: &Project) -> Result<Site, ReviewError> {
    let (heading, reviews) = review_project(project, true)?;
    Site::build(&heading, &reviews, Resources::Linked)
}
