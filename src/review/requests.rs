//! What the review server accepts, decided from the request line and headers alone, before
//! anything is read or written.
//!
//! - **Only this server's page.** The `Host` must be the server's own address (`127.0.0.1:PORT`
//!   or `localhost:PORT`), which stops a page on another site from reaching it through a DNS
//!   name that it points at 127.0.0.1 (DNS rebinding). An `Origin` must be the server's own, and
//!   a POST must carry one: browsers send it with every POST, so a form or script on another
//!   site cannot decide for the reviewer. A browser's `Sec-Fetch-Site` other than `same-origin`
//!   or `none` (typed in the address bar) is refused, so that another site cannot load the
//!   pages' pixel data as a script either.
//! - **Only the listed actions.** `GET` of the page or of a file it lists, `POST` of
//!   `/accept/NAME`, `/reject/NAME` and `/accept-all`. A file is looked up among the page's own
//!   files by its exact path, never opened from disk; a NAME must be a case name (letters,
//!   digits, `_`, `-`) and is then looked up among the pending goldens.

use super::pending::is_case_name;

/// What a request may do.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Route {
    /// The page, made again from the goldens pending now.
    Page,
    /// A file the page lists (`img/…`, `data/…`), by its path relative to the page.
    File(String),
    Accept(String),
    Reject(String),
    AcceptAll,
}

/// Why a request was refused: the HTTP status and a reason for the log and the answer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refusal {
    pub status: u16,
    pub reason: String,
}

fn refuse(status: u16, reason: impl Into<String>) -> Refusal {
    Refusal {
        status,
        reason: reason.into(),
    }
}

/// Decides what a request may do. `header` looks a header up by name (case-insensitively);
/// `port` is the server's.
pub fn route(method: &str, url: &str, header: impl Fn(&str) -> Option<String>, port: u16) -> Result<Route, Refusal> {
    let own_hosts = [format!("127.0.0.1:{port}"), format!("localhost:{port}")];
    match header("Host") {
        Some(host) if own_hosts.contains(&host.to_ascii_lowercase()) => {}
        Some(host) => return Err(refuse(403, format!("host `{host}` is not this server"))),
        None => return Err(refuse(403, "no Host header")),
    }
    let origin = header("Origin");
    if let Some(origin) = &origin
        && !own_hosts
            .iter()
            .any(|host| origin.eq_ignore_ascii_case(&format!("http://{host}")))
    {
        return Err(refuse(403, format!("origin `{origin}` is not this server's page")));
    }
    if let Some(site) = header("Sec-Fetch-Site")
        && !matches!(site.as_str(), "same-origin" | "none")
    {
        return Err(refuse(403, format!("a {site} request")));
    }
    let path = url.split(['?', '#']).next().unwrap_or_default();
    match method {
        "GET" | "HEAD" => match path {
            "/" | "/index.html" => Ok(Route::Page),
            _ => match path.strip_prefix('/') {
                Some(file) if file.starts_with("img/") || file.starts_with("data/") => Ok(Route::File(file.to_owned())),
                _ => Err(refuse(404, "no such page")),
            },
        },
        "POST" => {
            if origin.is_none() {
                return Err(refuse(
                    403,
                    "a POST without an Origin header (not from the review page)",
                ));
            }
            let name = |rest: &str| {
                if is_case_name(rest) {
                    Ok(rest.to_owned())
                } else {
                    Err(refuse(404, "not a case name"))
                }
            };
            if path == "/accept-all" {
                Ok(Route::AcceptAll)
            } else if let Some(rest) = path.strip_prefix("/accept/") {
                name(rest).map(Route::Accept)
            } else if let Some(rest) = path.strip_prefix("/reject/") {
                name(rest).map(Route::Reject)
            } else {
                Err(refuse(404, "unknown action"))
            }
        }
        _ => Err(refuse(405, format!("method {method} is not served"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn headers(list: &'static [(&'static str, &'static str)]) -> impl Fn(&str) -> Option<String> {
        move |name| {
            list.iter()
                .find(|(n, _)| n.eq_ignore_ascii_case(name))
                .map(|(_, v)| (*v).to_owned())
        }
    }

    const PAGE: &[(&str, &str)] = &[("Host", "127.0.0.1:8000"), ("Origin", "http://127.0.0.1:8000")];

    #[test]
    fn the_page_may_read_its_files_and_decide() {
        let h = headers(PAGE);
        assert_eq!(route("GET", "/", &h, 8000), Ok(Route::Page));
        assert_eq!(
            route("GET", "/img/a.heatmap.png", &h, 8000),
            Ok(Route::File("img/a.heatmap.png".into()))
        );
        assert_eq!(
            route("POST", "/accept/jitter_2", &h, 8000),
            Ok(Route::Accept("jitter_2".into()))
        );
        assert_eq!(route("POST", "/reject/a-b", &h, 8000), Ok(Route::Reject("a-b".into())));
        assert_eq!(route("POST", "/accept-all", &h, 8000), Ok(Route::AcceptAll));
        let typed = headers(&[("Host", "localhost:8000"), ("Sec-Fetch-Site", "none")]);
        assert_eq!(route("GET", "/?x", &typed, 8000), Ok(Route::Page));
    }

    #[test]
    fn anything_else_is_refused() {
        let h = headers(PAGE);
        let status =
            |method, url, h: &dyn Fn(&str) -> Option<String>| route(method, url, h, 8000).map_err(|r| r.status);
        assert_eq!(status("GET", "/../../etc/passwd", &h), Err(404));
        assert_eq!(status("POST", "/accept/..%2F..%2Fetc%2Fpasswd", &h), Err(404));
        assert_eq!(status("POST", "/accept/../x", &h), Err(404));
        assert_eq!(status("POST", "/delete/a", &h), Err(404));
        assert_eq!(status("PUT", "/accept/a", &h), Err(405));
        let other = headers(&[("Host", "127.0.0.1:8000"), ("Origin", "http://evil.example")]);
        assert_eq!(status("POST", "/accept/a", &other), Err(403));
        let no_origin = headers(&[("Host", "127.0.0.1:8000")]);
        assert_eq!(status("POST", "/accept/a", &no_origin), Err(403));
        let rebound = headers(&[("Host", "evil.example:8000")]);
        assert_eq!(status("GET", "/", &rebound), Err(403));
        let cross = headers(&[("Host", "127.0.0.1:8000"), ("Sec-Fetch-Site", "cross-site")]);
        assert_eq!(status("GET", "/data/a.js", &cross), Err(403));
        let other_port = headers(&[("Host", "127.0.0.1:8001")]);
        assert_eq!(status("GET", "/", &other_port), Err(403));
    }
}
