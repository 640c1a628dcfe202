"""roastlab.report"""
