;;> Metrics: how a component ranks its candidates -- the thesis's
;;> location and load metrics, metric-by and metric-by-asking, tolerance
;;> and composition -- and the measuring pose-task does with them.

(define-library (murdoch task metric)
  (export location-metric-maker load-metric-maker load-metric reverse-metric
          metric-by metric-by-asking metric-within compose-metrics
          reckon-distance-between sort-response
          metric-keys measure-key?
          measured-response asking-procs sort-measured shuffle)
  (import (scheme base) (scheme inexact) (scheme cxr) (srfi 1) (srfi 18) (srfi 27)
          (srfi 132) (only (chibi ast) procedure-code procedure-vars opcode?)
          (only (murdoch sys) map-guarded)
          (murdoch code) (murdoch remote) (murdoch pubsub) (murdoch robot)
          (murdoch task progress))
  (include "metric.scm"))
