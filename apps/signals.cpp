#include "signals.hpp"

#include <csignal>
#include <cstddef>

#include <signal.h>
#include <unistd.h>

namespace gpa::app {

namespace {

volatile std::sig_atomic_t stop_signal = 0;

// What the handler writes: chosen before the handlers are installed, only read in them.
const char with_checkpoint[] =
    "\ngpa: stopping after this step: a snapshot, a checkpoint and the summary follow (signal again to stop at once)\n";
const char without_checkpoint[] =
    "\ngpa: stopping after this step: a snapshot and the summary follow, but no checkpoint (element bodies cannot be "
    "checkpointed yet); signal again to stop at once\n";
const char* stop_message = with_checkpoint;
std::size_t stop_message_size = sizeof with_checkpoint - 1;
struct sigaction previous_int {}, previous_term {};

void on_stop_signal(int signo) {
    // Only async-signal-safe calls here: sigaction, write.
    stop_signal = signo;
    struct sigaction fallback {};
    fallback.sa_handler = SIG_DFL;
    sigemptyset(&fallback.sa_mask);
    ::sigaction(SIGINT, &fallback, nullptr);
    ::sigaction(SIGTERM, &fallback, nullptr);
    const ssize_t ignored = ::write(STDERR_FILENO, stop_message, stop_message_size);
    (void)ignored;
}

}  // namespace

StopRequests::StopRequests(bool checkpoint) {
    stop_signal = 0;
    stop_message = checkpoint ? with_checkpoint : without_checkpoint;
    stop_message_size = checkpoint ? sizeof with_checkpoint - 1 : sizeof without_checkpoint - 1;
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
