// atmos: stop signals during long work (see interrupt.h).
#include "base/interrupt.h"

namespace atmos {

namespace {

volatile sig_atomic_t g_stop_signal = 0;
volatile sig_atomic_t g_active_scopes = 0;

extern "C" void RecordStopSignal(int signal_number) { g_stop_signal = signal_number; }

}  // namespace

int StopSignalReceived() { return g_active_scopes > 0 ? static_cast<int>(g_stop_signal) : 0; }

const char* StopSignalName(int signal_number) {
    switch (signal_number) {
        case SIGINT:
            return "SIGINT";
        case SIGTERM:
            return "SIGTERM";
        case SIGHUP:
            return "SIGHUP";
        default:
            return "a signal";
    }
}

StopSignalScope::StopSignalScope(bool active) : active_(active) {
    if (!active_) return;
    g_stop_signal = 0;
    g_active_scopes = g_active_scopes + 1;
    struct sigaction action {};
    action.sa_handler = RecordStopSignal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESETHAND;
    sigaction(SIGINT, &action, &old_int_);
    sigaction(SIGTERM, &action, &old_term_);
    sigaction(SIGHUP, &action, &old_hup_);
}

StopSignalScope::~StopSignalScope() {
    if (!active_) return;
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
    sigaction(SIGHUP, &old_hup_, nullptr);
    g_active_scopes = g_active_scopes - 1;
}

}  // namespace atmos
