//! Parsers for the command line's small values: triples, image sizes.

use endocast_core::render::Filter;

/// Three comma-separated numbers.
fn parse_triple<T: std::str::FromStr>(text: &str) -> Result<[T; 3], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [a, b, c] = parts.as_slice() else {
        return Err(format!(
            "expected three comma-separated numbers, found {text:?}"
        ));
    };
    let parse = |s: &str| {
        s.parse::<T>()
            .map_err(|_| format!("{s:?} is not a valid number"))
    };
    Ok([parse(a)?, parse(b)?, parse(c)?])
}

/// Positive dimensions `X,Y,Z`.
pub fn parse_dims(text: &str) -> Result<[usize; 3], String> {
    let dims = parse_triple::<usize>(text)?;
    if dims.contains(&0) {
        return Err("dimensions must be positive".into());
    }
    Ok(dims)
}

/// Finite, positive spacing `X,Y,Z` in mm.
pub fn parse_spacing(text: &str) -> Result<[f64; 3], String> {
    let spacing = parse_triple::<f64>(text)?;
    if spacing.iter().any(|s| !s.is_finite() || *s <= 0.0) {
        return Err(format!(
            "spacing must be finite and positive, found {text:?}"
        ));
    }
    Ok(spacing)
}

/// A finite point or vector `X,Y,Z` (world mm).
pub fn parse_vec3(text: &str) -> Result<[f64; 3], String> {
    let v = parse_triple::<f64>(text)?;
    if v.iter().any(|c| !c.is_finite()) {
        return Err(format!("expected finite numbers, found {text:?}"));
    }
    Ok(v)
}

/// An image size `WxH` in pixels.
pub fn parse_size(text: &str) -> Result<[usize; 2], String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, found {text:?}"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<usize>()
            .ok()
            .filter(|&n| n > 0)
            .ok_or_else(|| format!("{s:?} is not a positive pixel count"))
    };
    Ok([parse(w)?, parse(h)?])
}

/// A reconstruction filter by name: `trilinear` or `bspline`.
pub fn parse_filter(text: &str) -> Result<Filter, String> {
    Filter::from_name(text).ok_or_else(|| format!("unknown filter {text:?}: trilinear or bspline"))
}

/// A pixel `X,Y`.
pub fn parse_pixel(text: &str) -> Result<[usize; 2], String> {
    let (x, y) = text
        .split_once(',')
        .ok_or_else(|| format!("expected X,Y, found {text:?}"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<usize>()
            .map_err(|_| format!("{s:?} is not a pixel index"))
    };
    Ok([parse(x)?, parse(y)?])
}
