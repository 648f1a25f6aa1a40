//! Copper's macros need the build script every Copper application has: it tells them
//! where to keep the index of interned log strings (`cu29-build`).
fn main() {
    cu29_build::setup();
}
