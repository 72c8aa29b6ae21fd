// A model that solves but looks wrong (an overlap the job does not declare, a body moved far against its size).
#pragma once

#include <string>

namespace contact {

// What is wrong, at which JSON pointer of the job ("/contacts/3", "/bodies/0"). A warning never changes the answer; a
// strict job (Problem::strict) is refused for one before the solve, and fails after it (docs/job-format.md,
// "Warnings").
struct Warning {
  std::string pointer;
  std::string message;
};

}  // namespace contact
