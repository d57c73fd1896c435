//! The models and the analyses' main types are `Send + Sync` (issue 33): no `RefCell` hides state
//! in them, so a model can be shared between threads (a sweep over a shared model, Python's
//! threads). A compile-time check: the test fails to build when a type loses either bound.

fn send_sync<T: Send + Sync>() {}

#[test]
fn models_and_analyses_are_send_and_sync_issue_33() {
    send_sync::<ancf::Model>();
    send_sync::<gebf::Model>();
    send_sync::<genalpha::GenAlpha<ancf::SkylineLu>>();
    send_sync::<genalpha::GenAlpha<genalpha::DenseLu>>();
    send_sync::<harness::statics::AeroStatic<'static, ancf::Model>>();
    send_sync::<harness::statics::AeroStatic<'static, gebf::Model>>();
    send_sync::<harness::loads::LoadModel>();
    send_sync::<uvlm::Uvlm>();
}
