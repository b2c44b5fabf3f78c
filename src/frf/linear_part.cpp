#include "frf/linear_part.hpp"
