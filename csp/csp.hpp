// The CSP runtime in one include: channels, ALT, Runtime, par, poison.
#pragma once

#include "csp/alt.hpp"
#include "csp/channel.hpp"
#include "csp/errors.hpp"
#include "csp/runtime.hpp"
#include "csp/scheduler.hpp"
