// Factorisations a cancel left running: solve() returns within a second of a cancel even inside a factorisation,
// which cannot be interrupted, by leaving it to finish on a thread of its own (solver/common/background.hpp). A
// program that may exit while one runs asks here. Included by contact/solve.hpp.
#pragma once

namespace contact {

// Factorisations a cancel left running (each ends within seconds and frees its memory). A program about to exit
// waits for them (wait_for_background_work with a bound) or, if it must exit at once, ends with std::_Exit after
// flushing its output: exiting normally while one runs may crash in the libraries' exit handlers.
bool background_work_running();
// How many of them run now: each holds a core and its memory until it ends (contactd counts them against its
// workers before it starts another job).
int abandoned_background_work();
// Waits until no such work runs or `seconds` passed; true when none runs.
bool wait_for_background_work(double seconds);

}  // namespace contact
