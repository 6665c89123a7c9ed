//! Scripted input for demos and tests: steps applied one per frame, as if typed or done
//! to the window (`--script "+,+,v,size:400x300,wait:3,s"`).

use super::error::{Result, ViewError};

/// One step of a script.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// A key as typed: `+ - v w f r s p`.
    Key(char),
    /// Turn the camera by degrees (yaw, pitch).
    Orbit(f64, f64),
    /// Multiply the camera distance.
    Zoom(f64),
    /// Move the camera in the picture plane, in picture heights.
    Pan(f64, f64),
    /// Ask the window system for this inner size (pixels).
    Size(u32, u32),
    /// Unmap / map the window: what minimizing does to a program without a window manager.
    Hide,
    Show,
    /// Minimize / restore through the window manager (no effect without one).
    Minimize,
    Restore,
    /// Do nothing for this many frames.
    Wait(u32),
}

fn number<T: std::str::FromStr>(step: &str, s: &str) -> Result<T> {
    s.trim().parse().map_err(|_| ViewError::Usage(format!("script step '{step}': '{s}' is not a number")))
}

/// Parses a comma-separated script (see [`Step`]).
pub fn parse_script(text: &str) -> Result<Vec<Step>> {
    let mut steps = Vec::new();
    for raw in text.split(',') {
        let step = raw.trim();
        if step.is_empty() {
            continue;
        }
        let mut parts = step.split(':');
        let head = parts.next().unwrap_or_default();
        let args: Vec<&str> = parts.collect();
        let pair = || -> Result<(f64, f64)> {
            match args.as_slice() {
                [a, b] => Ok((number(step, a)?, number(step, b)?)),
                _ => Err(ViewError::Usage(format!(
                    "script step '{step}' needs two numbers (e.g. {head}:10:5)"
                ))),
            }
        };
        steps.push(match (head, args.len()) {
            (k, 0) if k.chars().count() == 1 && "+-vwfrsp".contains(k) => {
                Step::Key(k.chars().next().unwrap_or('+'))
            }
            ("orbit", _) => {
                let (a, b) = pair()?;
                Step::Orbit(a, b)
            }
            ("pan", _) => {
                let (a, b) = pair()?;
                Step::Pan(a, b)
            }
            ("zoom", 1) => Step::Zoom(number(step, args[0])?),
            ("size", 1) => {
                let (w, h) = args[0].split_once(['x', 'X']).ok_or_else(|| {
                    ViewError::Usage(format!("script step '{step}': expected size:WIDTHxHEIGHT"))
                })?;
                Step::Size(number(step, w)?, number(step, h)?)
            }
            ("hide", 0) => Step::Hide,
            ("show", 0) => Step::Show,
            ("minimize", 0) => Step::Minimize,
            ("restore", 0) => Step::Restore,
            ("wait", 0) => Step::Wait(1),
            ("wait", 1) => Step::Wait(number(step, args[0])?),
            _ => {
                return Err(ViewError::Usage(format!(
                    "unknown script step '{step}' (steps are separated by commas, e.g. '+,+,v'; keys + - v w f r s p; \
                     orbit:DX:DY, pan:DX:DY, zoom:F, size:WxH, hide, show, minimize, restore, wait[:N])"
                )));
            }
        });
    }
    Ok(steps)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_every_step_and_rejects_nonsense() {
        let steps =
            parse_script("+, -,v,orbit:10:-5,zoom:0.5,pan:0.1:0,size:320x200,hide,show,wait,wait:3,s")
                .unwrap();
        assert_eq!(
            steps,
            vec![
                Step::Key('+'),
                Step::Key('-'),
                Step::Key('v'),
                Step::Orbit(10.0, -5.0),
                Step::Zoom(0.5),
                Step::Pan(0.1, 0.0),
                Step::Size(320, 200),
                Step::Hide,
                Step::Show,
                Step::Wait(1),
                Step::Wait(3),
                Step::Key('s'),
            ]
        );
        for bad in ["x", "orbit:1", "size:12", "zoom:a", "wait:-1"] {
            assert!(parse_script(bad).is_err(), "{bad}");
        }
    }
}
