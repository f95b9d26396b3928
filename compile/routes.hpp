// The compile pass that chooses how a model's equations are computed, once, from the facts the
// other passes found: Model::mass_route, force_route and dynamics_route (or those asked), the
// factorisation of M^s (Model::mass_pattern), and from them Model::routes, the table every
// equations function calls through (core/model/routes.hpp). The only writer of these.
#pragma once
#include "core/model/model.hpp"

namespace femdyn {

// A model with a coupling law takes the law chain; any other the routes its structure makes
// exact and fastest, or those `asked` (ModelError for a body-level route where it is not
// exact).
void choose_routes(Model& model, const RouteChoice& asked = {});

// The routes the passes before choose_routes run the kinematics by (the node level's sampling of
// T): the reference ones of the model as built so far, no law. choose_routes replaces them.
void provisional_routes(Model& model);

}  // namespace femdyn
