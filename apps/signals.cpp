#include "signals.hpp"

#include <csignal>
#include <cstddef>

#include <signal.h>
#include <unistd.h>

namespace gpa::app {

namespace {

volatile std::sig_atomic_t stop_signal = 0;

// What the handler writes: chosen before the handlers are installed, only read in them.
const char stop_message[] =
    "\ngpa: stopping after this step: a snapshot, a checkpoint and the summary follow (signal again to stop at once)\n";
struct sigaction previous_int {}, previous_term {};

void on_stop_signal(int signo) {
    // Only async-signal-safe calls here: sigaction, write.
    stop_signal = signo;
    struct sigaction fallback {};
    fallback.sa_handler = SIG_DFL;
    sigemptyset(&fallback.sa_mask);
    ::sigaction(SIGINT, &fallback, nullptr);
    ::sigaction(SIGTERM, &fallback, nullptr);
    const ssize_t ignored = ::write(STDERR_FILENO, stop_message, sizeof stop_message - 1);
    (void)ignored;
}

}  // namespace

StopRequests::StopRequests() {
    stop_signal = 0;
    struct sigaction action {};
    action.sa_handler = on_stop_signal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    ::sigaction(SIGINT, &action, &previous_int);
    ::sigaction(SIGTERM, &action, &previous_term);
}

StopRequests::~StopRequests() {
    ::sigaction(SIGINT, &previous_int, nullptr);
    ::sigaction(SIGTERM, &previous_term, nullptr);
}

int StopRequests::requested() { return stop_signal; }

}  // namespace gpa::app
