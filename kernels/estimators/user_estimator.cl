/* Stands in for a user's estimator: `mcrt render --estimator-file FILE.cl` puts FILE's text here
 * (host/render/variants.cpp), with #line markers naming FILE. Empty for the built-in estimators. */
