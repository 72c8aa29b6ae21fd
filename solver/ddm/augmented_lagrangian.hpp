// The augmented Lagrangian around a penalty method: Uzawa updates of the contact multipliers, Anderson-mixed.
#pragma once

#include "driver.hpp"

namespace contact::ddm {

// Augmented Lagrangian (Uzawa): solve the penalty problem on the gaps shifted by theta lambda, then set lambda to
// the resulting pressures; repeat until the pressures settle (augmented_lagrangian.cpp). The outcome counts the
// updates.
void run_augmented_lagrangian(const ContactSystem& system, RunFrame& frame, ContactMethod& method);

}  // namespace contact::ddm
