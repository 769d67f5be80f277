//! What differs between the desktop and the web page, in one place: choosing a file to open,
//! choosing where to save, handing the user a file, and a clock. The rest of the app is the same on
//! both and never imports the web entry (`web.rs`).

#[cfg(not(target_arch = "wasm32"))]
pub use native::*;
#[cfg(target_arch = "wasm32")]
pub use web::*;

#[cfg(not(target_arch = "wasm32"))]
mod native {
    use std::path::PathBuf;

    /// Milliseconds on a monotonic clock (for time budgets within a frame).
    pub fn now_ms() -> f64 {
        static START: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();
        START
            .get_or_init(std::time::Instant::now)
            .elapsed()
            .as_secs_f64()
            * 1e3
    }

    /// The native open dialog (blocking): the chosen file, if any.
    pub fn choose_file_to_open(filter: &str, extensions: &[&str]) -> Option<PathBuf> {
        rfd::FileDialog::new()
            .add_filter(filter, extensions)
            .pick_file()
    }

    /// The native save dialog (blocking), suggesting `file_name`: the chosen path, if any.
    pub fn choose_file_to_save(
        filter: &str,
        extensions: &[&str],
        file_name: &str,
    ) -> Option<PathBuf> {
        rfd::FileDialog::new()
            .add_filter(filter, extensions)
            .set_file_name(file_name)
            .save_file()
    }
}

#[cfg(target_arch = "wasm32")]
mod web {
    use wasm_bindgen::JsCast;
    use wasm_bindgen::prelude::*;

    /// Lets the user pick a file with the browser's file picker (offering `accept`) and returns
    /// (name, bytes), or `None` if nothing was picked. Files over the size limit are refused
    /// unread.
    pub async fn pick_file(accept: &str) -> Option<(String, Result<Vec<u8>, String>)> {
        let document = web_sys::window()?.document()?;
        let input: web_sys::HtmlInputElement =
            document.create_element("input").ok()?.dyn_into().ok()?;
        input.set_type("file");
        input.set_accept(accept);
        // A promise the input's change event resolves.
        let changed = js_sys::Promise::new(&mut |resolve, _reject| {
            input.set_onchange(Some(&resolve));
        });
        input.click();
        let _ = wasm_bindgen_futures::JsFuture::from(changed).await;
        let file = input.files()?.get(0)?;
        let name = file.name();
        if let Err(e) = crate::io::project::check_size(file.size() as u64) {
            return Some((name, Err(e.to_string())));
        }
        let buffer = wasm_bindgen_futures::JsFuture::from(file.array_buffer()).await;
        Some((
            name,
            buffer
                .map(|b| js_sys::Uint8Array::new(&b).to_vec())
                .map_err(|_| "the file could not be read".to_string()),
        ))
    }

    /// Milliseconds since an arbitrary start (the browser's clock; std's `Instant` panics in
    /// wasm32), for time budgets within a frame.
    pub fn now_ms() -> f64 {
        js_sys::Date::now()
    }

    /// Offers `bytes` to the user as a downloaded file called `name` of MIME type `mime`.
    pub fn download(name: &str, bytes: &[u8], mime: &str) -> Result<(), String> {
        let js = |e: JsValue| format!("{e:?}");
        let window = web_sys::window().ok_or("no window")?;
        let document = window.document().ok_or("no document")?;
        let parts = js_sys::Array::of1(&js_sys::Uint8Array::from(bytes));
        let options = web_sys::BlobPropertyBag::new();
        options.set_type(mime);
        let blob =
            web_sys::Blob::new_with_u8_array_sequence_and_options(&parts, &options).map_err(js)?;
        let url = web_sys::Url::create_object_url_with_blob(&blob).map_err(js)?;
        let anchor: web_sys::HtmlAnchorElement = document
            .create_element("a")
            .map_err(js)?
            .dyn_into()
            .map_err(|_| "not an anchor".to_string())?;
        anchor.set_href(&url);
        anchor.set_download(name);
        anchor.click();
        web_sys::Url::revoke_object_url(&url).map_err(js)?;
        Ok(())
    }
}
