//! The validation layer is on under `tools/test` and a synchronization hazard fails the
//! submission (lavapipe would often compute the right answer anyway).

use texgeo::gpu::{Attachment, Buffer, Context, GpuError, Load, TexFormat, Texture, XorRaster};

fn validation_requested() -> bool {
    std::env::var("TEXGEO_VALIDATION").is_ok_and(|v| v == "1")
}

#[test]
fn validation_is_on_when_requested() {
    let ctx = Context::from_env().unwrap();
    assert_eq!(ctx.validating(), validation_requested());
    if std::env::var("TEXGEO_REQUIRE_VALIDATION").is_ok() {
        assert!(ctx.validating(), "tools/test must run the suite with the validation layer");
    }
}

#[test]
fn missing_barrier_is_reported() {
    if !validation_requested() {
        eprintln!("validation off: nothing to check here (tools/test turns it on)");
        return;
    }
    let ctx = Context::from_env().unwrap();
    let xor = XorRaster::new(&ctx, TexFormat::R32Ui).unwrap();
    let target = Texture::new(&ctx, TexFormat::R32Ui, 8, 8, "hazard").unwrap();
    let tri: Vec<[f32; 2]> = vec![[0.0, 0.0], [8.0, 0.0], [0.0, 8.0]];
    let vb = Buffer::with_data(&ctx, &tri, "tri").unwrap();
    let result = ctx.submit(|rec| {
        rec.render(&[Attachment::new(&target, Load::Zero)], None, &[], |p| xor.draw(p, &vb, 3, [8, 8], 1))?;
        // Copy out without the attachment→transfer barrier: a write-after-read hazard.
        rec.skip_next_barrier_for_test(&target, false);
        rec.readback(&target)
    });
    match result {
        Err(GpuError::Validation(msgs)) => {
            eprintln!("{}", msgs.join("\n"));
            assert!(!msgs.is_empty())
        }
        Err(e) => panic!("expected a validation error, got {e}"),
        Ok(_) => panic!("the missing barrier went unnoticed"),
    }
}
