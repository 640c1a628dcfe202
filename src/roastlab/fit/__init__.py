"""roastlab.fit"""
