#pragma once
// The built-in constellation: broadcast navigation records for GPS, GLONASS, Galileo and BeiDou (MEO), written out as
// RINEX 3 navigation so that any reader (canyon's, RTKLIB's) computes the same satellites.
//
// Orbits (one fixed set of elements, independent of the scenario seed: the sky of a given date is the same in every
// scenario):
//  - GPS: 6 planes 60 deg apart, inclination 55 deg, a = 26 559.7 km, four unevenly phased slots per plane (24
//    nominal slots) and up to 8 spares placed in the largest in-plane gaps.
//  - GLONASS: 3 planes 120 deg apart, inclination 64.8 deg, a = 25 508 km, 8 slots per plane 45 deg apart, planes
//    phased by 15 deg; FDMA channels as in the current slot/channel plan (antipodal slots share a channel).
//  - Galileo: Walker 24/3/1, inclination 56 deg, a = 29 600 km.  BeiDou: MEO Walker 24/3/1, 55 deg, a = 27 906 km
//    (C19..C42; no GEO or IGSO).
// Small eccentricities, argument of perigee and inclination offsets are drawn once from a fixed generator.
//
// Kepler records (GPS every 2 h, Galileo every 10 min I/NAV, BeiDou every hour) carry a precessing Kepler orbit: the
// J2 secular node rate (OMEGA DOT) and mean-motion correction (Delta n), no harmonic terms. Every record of a
// satellite describes the same orbit (M0, OMEGA0 and af0 are propagated to each toe), so switching records never
// makes the satellite jump. GLONASS records (every 30 min at tb = hh:15 and hh:45 UTC) are the PZ-90 state of one
// reference trajectory integrated with the broadcast force model (central term, J2, rotating frame, no lunisolar
// term, matching the written zero acceleration) by 4th-order Runge-Kutta in 10 s steps, so that a reader's
// integration from any record reproduces the others to well below a millimetre.
//
// Clocks: af0 up to +-0.5 ms, af1 up to +-5e-12 s/s (GLONASS tau_n, gamma_n likewise), group delays (TGD, BGD) up to
// +-8 ns; health 0; accuracy 2 m (Galileo SISA 3.12 m).

#include "canyon/core/ephemeris.hpp"
#include "canyon/core/time.hpp"
#include "canyon/sim/scenario.hpp"

namespace canyon::sim {

/// Broadcast records of the built-in constellation covering [t_begin, t_end] with margin for every reader's
/// selection rules (GPS and BeiDou from 2 h before to 2 h after, Galileo and GLONASS 1 h).
[[nodiscard]] core::NavigationData builtin_navigation(const ConstellationOptions& options, core::GpsTime t_begin,
                                                      core::GpsTime t_end);

/// Satellites of the built-in constellation for the enabled systems.
[[nodiscard]] std::vector<core::SatelliteId> builtin_satellites(const ConstellationOptions& options);

}  // namespace canyon::sim
