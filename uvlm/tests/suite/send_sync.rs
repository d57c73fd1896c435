//! The solver types hold their scratch space as explicit workspaces (no `RefCell`, no
//! thread-local state), so they can move to and be shared between threads: a compile-time check.

use uvlm::*;

fn assert_send_sync<T: Send + Sync>() {}

#[test]
fn solver_types_are_send_and_sync() {
    assert_send_sync::<Uvlm>();
    assert_send_sync::<Surface>();
    assert_send_sync::<LinearUvlm>();
    assert_send_sync::<LinearGust>();
    assert_send_sync::<Treecode>();
    assert_send_sync::<Flow>();
    assert_send_sync::<Lattice>();
    assert_send_sync::<Wake>();
    assert_send_sync::<Filaments>();
    assert_send_sync::<Loads>();
    assert_send_sync::<UvlmParams>();
    assert_send_sync::<VonKarman>();
}
